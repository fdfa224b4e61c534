#pragma once
// Tracking of vertical lines across a video (Sec. 9.1), plus the constraints the paper names
// as its next step (mutual assignment, and a gate from wheel odometry).
//
// For each new frame t, every line is matched (Matcher, tests 1-3 of Sec. 4) against the
// lines of frame t-1; a line with no accepted match there is matched against frame t-2, and
// so on up to `look_back` frames back (20 in the paper). A line with no accepted match in any
// of them starts a new track. A matched line takes the track id of the line it matched.
// Track ids are 0, 1, 2, ... in order of creation and never reused.
//
// In each look-back frame the candidate set is that frame's full set of lines, so tests 2 and
// 3 measure distinctiveness within one image as in the paper; earlier frames are searched
// only for the lines still unmatched (the most recent frame wins).
//
// Optional constraints (off by default = the paper's three rules alone):
//  - mutual: the nearest candidate B_j of A_i must have A_i as its nearest line among all
//    lines of the new frame (mutual nearest neighbours), and a track already claimed by a
//    line of the new frame (in a more recent look-back frame) cannot be claimed again. With
//    it, a track holds at most one line per frame. Without it, two lines of one frame can
//    take the same id (the paper's behaviour).
//  - odometry gate (odometry_gate.hpp): an accepted match whose bearing change contradicts
//    the wheel travel since the candidate frame is vetoed; the line goes on looking back.
//  - same polarity, gate-restricted candidates, track continuity, look-back F1, heads only,
//    confirmed F1: see TrackerOptions and docs/theory/matching.md (recommended_tracker_options()
//    turns on mutual, the gate, same polarity and continuity with the track model, with F1 0.6,
//    look-back F1 0.5 and confirmed F1 1.05 at 0.3 degree).
//
// Bookkeeping: a ring buffer holds the last `look_back` frames (descriptors, bearings, track
// ids, accumulated odometry). Buffers grow to the largest frame seen and are then reused: no
// allocation per frame in steady state.

#include <cstdint>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "omnivert/describe/frame_features.hpp"
#include "omnivert/match/matcher.hpp"
#include "omnivert/match/odometry_gate.hpp"
#include "omnivert/match/track_geometry.hpp"

namespace omnivert {

struct TrackerOptions {
  MatchOptions match;        // tests 1-3 (Sec. 4)
  int look_back = 20;        // frames searched back for an unmatched line (Sec. 9.1)
  bool mutual = false;       // one-to-one, mutual nearest neighbours
  OdometryGateOptions gate;  // bearing-change gate from wheel travel (off by default)
  // With the gate on: the nearest and second-nearest candidates of tests 1 and 3 (and the
  // mutual check) are taken among the lines the gate admits, instead of the gate vetoing the
  // nearest of all lines afterwards. Test 2's mean stays over all lines of the frame. A
  // look-alike that the wheels rule out then neither wins nor makes the true line fail test 3
  // (docs/theory/matching.md, measured there).
  bool gate_candidates = false;
  // Candidates of the opposite edge polarity (VerticalLine::polarity; 0 = unknown matches
  // anything) are left out of tests 1-3 and the mutual check. The two sides of a thin door
  // frame look alike to the descriptor but have opposite polarities: where extraction finds
  // them in turn, the paper's rules link them (docs/theory/matching.md, measured there).
  bool same_polarity = false;
  // Track continuity (needs the odometry gate's wheel data; 0 = off): a link to track T is
  // refused when the new bearing deviates from T's predicted one by more than this (radians)
  // plus the gate's camera-swing term. The prediction removes the robot's rotation (eq. 16) and
  // extrapolates the parallax per metre driven of the observation linked to, measured on that
  // observation's own link when it spans at most 3 frames (otherwise the link is not checked).
  // It targets two close edges that extraction finds in turn.
  double continuity_tolerance = 0.0;
  // How track continuity predicts (docs/theory/matching.md):
  //  - kLink: the parallax per metre of the observation linked to, measured on its own link
  //    when that spans at most 3 frames; links to other observations are not checked, and
  //    rotation is covered by the gate's camera-swing bound alone.
  //  - kTrack: each observation carries its track's parallax per metre driven AND per radian
  //    turned (the camera swings around the axle during turns on the spot), measured on its
  //    link (at most 3 frames) and otherwise inherited along the track, so links across a
  //    look-back gap and during turns are checked too. What the rates cannot predict is
  //    bounded by continuity_path_curvature * path^2 + continuity_turn_curvature * d_theta^2
  //    (each capped by the sound bound of the gate: asin(s / D_min)); an unknown rate falls
  //    back to the sound bound of its motion.
  enum class ContinuityModel { kLink, kTrack };
  ContinuityModel continuity_model = ContinuityModel::kLink;
  double continuity_path_curvature = 0.5;  // rad per m^2 (kTrack)
  double continuity_turn_curvature = 0.3;  // rad per rad^2 (kTrack)
  // Test 1 for links across a look-back gap (frames t-2 .. t-look_back): min D_i <= this
  // (0 = F1, as in the paper). Descriptors of a line change with the viewpoint; a link across
  // a gap is less certain and needs a closer descriptor (docs/theory/matching.md).
  double look_back_f1 = 0.0;
  // Look-back links only to a track's latest observation: a line of frame t-k (k >= 2) whose
  // track was observed again in frames t-k+1 .. t-1 cannot be linked to (the line then goes on
  // looking back). Look-back bridges frames where a line was missed; a link to an older
  // observation of a track seen since would fork it (two lines that extraction finds in turn
  // become one track; docs/theory/matching.md).
  bool heads_only = false;
  // Confirmed F1 (needs track continuity; 0 = off): a link whose descriptor distance fails
  // test 1 (F1, or look_back_f1 across a gap) but is at most confirm_f1 is accepted when tests
  // 2 and 3 pass with F1 = confirm_f1 and the track's motion confirms it: its rates are known,
  // the new bearing is within confirm_tolerance (plus the model's curvature terms) of the
  // prediction, and no other line of the new frame is within continuity_tolerance of it. A
  // line's descriptor changes fastest where its bearing does (near lines); there the
  // geometry is most telling (docs/theory/matching.md).
  double confirm_f1 = 0.0;
  double confirm_tolerance = 0.0;  // radians
  // Triangulated prediction (needs track continuity with the track model): each track's line is
  // located from two of its bearings during straight travel and the wheels' travel in between
  // (track_geometry.hpp), and the track's bearing in the new frame is predicted from that
  // position instead of from its rates while the robot has not turned since. The camera's yaw
  // on the robot (phi + psi) is `camera_yaw` when given (finite), else estimated from the sign
  // of the tracks' parallax (CameraYawVotes).
  bool triangulate = false;
  double camera_yaw = std::numeric_limits<double>::quiet_NaN();
  // Links by prediction (needs `triangulate`; 0 = off): a line still unmatched after the
  // descriptor's look-back is linked to the latest observation, within the look-back, of a track
  // whose triangulated prediction it meets within confirm_tolerance (plus the prediction's
  // spread), when no other line of that edge polarity lies within continuity_tolerance of the
  // prediction, no other track predicts the line that closely, and their descriptor distance is
  // at most predict_f1. Far apart frames change a near line's descriptor beyond test 1 and make
  // tests 2 and 3 pick look-alikes; the wheels still say where the line is.
  double predict_f1 = 0.0;

  bool IsValid(std::string* error) const;
};

// The paper's tracker alone: tests 1-3 with Table 2's factors, look-back 20 (Sec. 9.1).
TrackerOptions paper_tracker_options();
// What we recommend (docs/theory/matching.md, measured there): the paper's rules with F1 = 0.6 and
// 0.5 across a look-back gap, plus the mutual constraint, same edge polarity, and the odometry
// gate with track continuity (track model, 0.8 degree), confirmed F1 (1.05 where the track
// predicts the line to 0.3 degree), the triangulated prediction and links by prediction up to
// F1 1.05, when the wheel base is known (wheel_base > 0; pass 0 when there is no odometry).
TrackerOptions recommended_tracker_options(double wheel_base);
// The recommended set for a whole dataset (track_dataset, pipeline::calibrate_dataset, the
// CLI): the odometry gate on, its wheel base filled in from wheel0/sensor.yaml by
// track_dataset (which turns the gate off when the dataset has no wheel data).
TrackerOptions recommended_dataset_tracker_options();

// Why a line of frame t was or was not linked to a line of an earlier frame (TrackerOptions:
// the first rule that refused it).
enum class LinkVerdict : std::int8_t {
  kLinked,
  kNoFrame,       // no such frame, or it has no lines
  kNoCandidates,  // no admissible candidate (edge polarity, gate-restricted candidates)
  kTest1,
  kTest2,
  kTest3,
  kLookBackF1,
  kMutual,
  kClaimed,
  kGate,
  kContinuity,
  kFork,
};
const char* to_string(LinkVerdict v);

// What the tracker decided for one line of a frame.
struct TrackAssignment {
  std::int64_t track_id = -1;
  // How many frames back the matched line was (1 = previous frame); 0 for a new track.
  int frames_back = 0;
  // Index of the matched line in that frame; -1 for a new track.
  int matched_line = -1;
  float distance = 0.0f;  // descriptor distance of the match (0 for a new track)
  // Frame t-1: why the line was not linked there (kLinked when it was), and the candidate
  // looked at (index in frame t-1, -1 when none) with its descriptor distance.
  LinkVerdict previous_verdict = LinkVerdict::kNoFrame;
  int previous_candidate = -1;
  float previous_distance = 0.0f;
  bool is_new() const { return frames_back == 0; }
};

// Counters over a run: each rule's effect is visible here (docs/tracking.md).
struct TrackerStats {
  std::int64_t frames = 0;
  std::int64_t lines = 0;
  std::int64_t matched_previous = 0;   // matched in frame t-1
  std::int64_t matched_look_back = 0;  // matched in frames t-2 .. t-look_back
  std::int64_t new_tracks = 0;
  // Rejections of a best candidate, over all look-back attempts (one line can count several
  // times, once per frame it was tried against).
  std::int64_t rejected_test1 = 0;
  std::int64_t rejected_test2 = 0;
  std::int64_t rejected_test3 = 0;
  std::int64_t rejected_mutual = 0;      // not mutual nearest neighbours
  std::int64_t rejected_claimed = 0;     // track already taken in this frame (mutual on)
  std::int64_t rejected_gate = 0;        // odometry gate veto
  std::int64_t rejected_continuity = 0;  // track continuity veto
  std::int64_t rejected_fork = 0;        // heads_only: track observed since that frame
  std::int64_t linked_by_prediction = 0;
  std::string BriefReport() const;
};

class Tracker {
 public:
  // Throws InputError with the reason when the options are not valid (TrackerOptions::IsValid).
  explicit Tracker(TrackerOptions options);

  // Processes the next frame. `since_previous` is the wheel travel from the previous frame
  // to this one (ignored for the first frame and when the gate is off). A frame that could
  // not be read should still be passed, with no lines, so that frame counts and odometry
  // stay right. `out` is resized to the number of lines, in line order. Throws
  // std::invalid_argument when the descriptors do not have one row per line or change width.
  void add_frame(const FrameFeatures& frame,
                 const WheelIncrement& since_previous,
                 std::vector<TrackAssignment>* out);
  // Same, without odometry (the gate must be off; std::invalid_argument otherwise).
  void add_frame(const FrameFeatures& frame, std::vector<TrackAssignment>* out);

  // The camera's yaw on the robot (phi + psi, radians) from the next frame on, e.g. a running
  // calibration's estimate; NaN: estimated by the tracker again (TrackerOptions::camera_yaw).
  // The lines already located keep the yaw they were located with (Sec. 9.1's prediction).
  void set_camera_yaw(double yaw) { options_.camera_yaw = yaw; }

  const TrackerOptions& options() const { return options_; }
  const TrackerStats& stats() const { return stats_; }
  std::int64_t frames_seen() const { return frame_count_; }
  std::int64_t tracks_created() const { return next_track_id_; }

 private:
  // TrackerOptions::triangulate: where a line's track began its current straight stretch (the
  // anchor: the axle's position, the rotation-free bearing u = beta + theta and the heading) and
  // the line's position triangulated from the anchor, with the heading it was found at (NaN:
  // unknown).
  struct LineGeometry {
    static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    double ax = kNaN, ay = kNaN, au = kNaN, a_theta = kNaN;
    // The line's position (world), triangulated at heading p_theta with the camera's yaw
    // p_yaw: the prediction uses that same yaw, so that a later estimate of the yaw does not
    // turn every predicted bearing by its change.
    double px = kNaN, py = kNaN, p_theta = kNaN, p_yaw = kNaN;
    bool fresh = false;  // the observation began its track
  };
  struct Slot {
    DescriptorMatrix descriptors;  // capacity rows; the first `num_lines` are live
    std::vector<double> bearings;
    std::vector<int> polarities;
    std::vector<double> parallax_rates;  // continuity: rad per metre driven, NaN = unknown
    std::vector<double> turn_rates;      // continuity (kTrack): rad per rad turned, NaN = unknown
    std::vector<LineGeometry> geometry;  // TrackerOptions::triangulate
    std::vector<std::int64_t> track_ids;
    int num_lines = 0;
    OdometryAccumulator odometry;
  };

  // The candidates of frame t-k for the lines of the new frame still unmatched (query rows):
  // their descriptor distances (the Matcher's last call), the odometry gate since frame t-k,
  // and whether some candidates are left out (same polarity, gate-restricted candidates).
  struct CandidateSearch {
    int k = 0;
    const Slot* slot = nullptr;
    int num_queries = 0;
    bool all_rows = false;  // every line of the new frame is a query: row q is line q
    BearingGate gate;
    bool gate_restricts = false;  // TrackerOptions::gate_candidates with an informative gate
    bool restricted = false;      // gate_restricts or TrackerOptions::same_polarity
  };
  // Whether line `line` of the new frame is linked to its best candidate, and if not, the
  // first rule that refused it.
  struct LinkDecision {
    bool ok = false;
    LinkVerdict why = LinkVerdict::kNoCandidates;
    std::int64_t track_id = -1;
  };

  // The slot of frame (frame_count_ - k), k = 1..look_back; requires k <= frames held.
  Slot& slot_back(int k);
  const Slot& slot_back(int k) const;

  // Steps of add_frame.
  void check_frame(const FrameFeatures& frame) const;
  void begin_frame(const FrameFeatures& frame,
                   const WheelIncrement& since_previous,
                   std::vector<TrackAssignment>* out);
  CandidateSearch search_candidates(const FrameFeatures& frame, int k);
  void match_queries(const FrameFeatures& frame, const CandidateSearch& c);
  // May line `a` of the new frame be matched to line `j` of frame t-k?
  bool admissible(const FrameFeatures& frame, const CandidateSearch& c, int a, int j) const;
  // Tests 1 and 3 among the admissible candidates only (test 2's mean over all of them).
  void retest_admissible(const FrameFeatures& frame, const CandidateSearch& c);
  void link_lines(const FrameFeatures& frame,
                  const CandidateSearch& c,
                  std::vector<TrackAssignment>* out);
  LinkDecision decide_link(const FrameFeatures& frame,
                           const CandidateSearch& c,
                           int line,
                           const MatchResult& r);
  void start_new_tracks(std::vector<TrackAssignment>* out);
  void store_frame(const FrameFeatures& frame, const std::vector<TrackAssignment>& out);

  // The rules of the link decision (decide_link), in the order they are applied.
  // Test 1 with TrackerOptions::look_back_f1 for a link across a gap.
  bool refused_by_look_back_f1(int k, const MatchResult& r) const;
  // TrackerOptions::confirm_f1: a link refused by test 1 alone (F1 or the look-back F1, `why`)
  // that passes tests 1-3 with F1 = confirm_f1, for the track to confirm.
  bool needs_confirmation(const CandidateSearch& c, const MatchResult& r, LinkVerdict why) const;
  // The rules below count their rejections in stats_ and return LinkVerdict::kLinked when they
  // do not refuse the link.
  // Tests 1-3 of Sec. 4 (the Matcher's verdict); a test 1 failure to be confirmed is not
  // counted here.
  LinkVerdict match_test_verdict(const MatchResult& r, bool needs_confirmation);
  // TrackerOptions::mutual: mutual nearest neighbours, and one line per track and frame.
  LinkVerdict mutual_verdict(const FrameFeatures& frame,
                             const CandidateSearch& c,
                             int line,
                             const MatchResult& r,
                             std::int64_t id);
  // The nearest line of the new frame to line j of frame t-k (among the admissible ones when
  // candidates are restricted), ties to the lowest index.
  int nearest_new_line(const FrameFeatures& frame, const CandidateSearch& c, int j) const;
  // The odometry gate's veto.
  LinkVerdict gate_verdict(const FrameFeatures& frame,
                           const CandidateSearch& c,
                           int line,
                           const MatchResult& r);
  // Track continuity, and the confirmation of a confirmed-F1 link (refused as `f1_verdict`).
  LinkVerdict continuity_verdict(const FrameFeatures& frame,
                                 int k,
                                 int line,
                                 const MatchResult& r,
                                 bool needs_confirmation,
                                 LinkVerdict f1_verdict);
  // TrackerOptions::heads_only.
  LinkVerdict fork_verdict(int k, std::int64_t id);
  bool track_claimed(std::int64_t id) const;
  // The rotation-free bearing u = beta + theta that track continuity predicts for the track of
  // line j of frame t-k in the new frame, and the spread its model allows on top of the
  // tolerance (curvature and sound bounds).
  struct TrackPrediction {
    double u = 0.0;
    double spread = 0.0;
    bool rates_known = true;    // the motion since frame t-k is covered by measured rates
    bool triangulated = false;  // predicted from the line's position (TrackerOptions::triangulate)
  };
  // The prediction from the line's triangulated position, when there is one.
  bool predict_from_position(const Slot& s, int j, TrackPrediction* p) const;
  TrackPrediction predict_track(int k, int j) const;
  // TrackerOptions::continuity_tolerance: may line `bearing` of the new frame continue the
  // track predicted by p?
  bool continues_track(const TrackPrediction& p, double bearing) const;
  // TrackerOptions::confirm_f1: does the track predicted by p predict line `line` of `frame`,
  // and no other line of it?
  bool confirms_track(const TrackPrediction& p, const FrameFeatures& frame, int line) const;
  // TrackerOptions::heads_only: was track `id` observed in frames t-k+1 .. t-1?
  bool observed_since(std::int64_t id, int k);
  // Track continuity: the rates (parallax per metre driven, per radian turned) of each line
  // of the new frame, into rates_ and turn_rates_, before its slot is stored.
  void measure_track_rates(const FrameFeatures& frame, const std::vector<TrackAssignment>& out);
  std::vector<double> rates_, turn_rates_;  // work space of store_frame
  // TrackerOptions::triangulate: each line's anchor and position, into geometry_, and the votes
  // on the camera's yaw, before its slot is stored.
  void measure_track_geometry(const FrameFeatures& frame, const std::vector<TrackAssignment>& out);
  std::vector<LineGeometry> geometry_;
  CameraYawVotes yaw_votes_;
  double camera_yaw_ = std::numeric_limits<double>::quiet_NaN();  // given or estimated
  // TrackerOptions::predict_f1: links by prediction of the lines still unmatched.
  void link_by_prediction(const FrameFeatures& frame, std::vector<TrackAssignment>* out);
  struct Head {
    int k = 0, j = 0;
    double u = 0.0, tight = 0.0, wide = 0.0;
  };
  std::vector<Head> heads_;
  // Heads from pairs: a track begun in frame t-1 and the latest observation, in frame t-2, of
  // another, whose rays meet (link_by_prediction).
  void add_pair_heads();
  std::vector<std::tuple<std::int64_t, int, int>>
      latest_;  // (track, k, line) of link_by_prediction

  TrackerOptions options_;
  Matcher matcher_;
  std::vector<Slot> ring_;
  std::int64_t frame_count_ = 0;
  std::int64_t next_track_id_ = 0;
  OdometryAccumulator odometry_;
  Eigen::Index descriptor_width_ = 0;
  TrackerStats stats_;
  // Per-frame work space.
  std::vector<int> unmatched_;
  std::vector<int> still_unmatched_;
  std::vector<std::int64_t> claimed_;
  DescriptorMatrix query_;
  std::vector<MatchResult> results_;
};

}  // namespace omnivert
