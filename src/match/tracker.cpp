#include "omnivert/match/tracker.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert {
namespace {

// Capacity for a frame of n lines: at least 64 (frames have 20-40 lines), else the next power
// of two, so that buffers reach their final size after a few frames and then stay.
Eigen::Index line_capacity(Eigen::Index n) {
  return std::max<Eigen::Index>(64,
                                static_cast<Eigen::Index>(std::bit_ceil(
                                    static_cast<std::size_t>(std::max<Eigen::Index>(n, 1)))));
}

}  // namespace

bool TrackerOptions::IsValid(std::string* error) const {
  if (!match.IsValid(error)) return false;
  if (look_back < 1 || look_back > 1000) {
    if (error) *error = "look-back must be between 1 and 1000 frames (paper: 20)";
    return false;
  }
  if (!(continuity_tolerance >= 0.0 && continuity_tolerance < kPi)) {
    if (error) *error = "continuity tolerance must be in [0, pi) radians (0: off)";
    return false;
  }
  if (!(continuity_path_curvature >= 0.0 && continuity_turn_curvature >= 0.0 &&
        std::isfinite(continuity_path_curvature) && std::isfinite(continuity_turn_curvature))) {
    if (error) *error = "continuity curvature bounds must be finite and >= 0";
    return false;
  }
  if (!(confirm_f1 >= 0.0 && std::isfinite(confirm_f1) && confirm_tolerance >= 0.0 &&
        confirm_tolerance < kPi)) {
    if (error) *error = "confirmed F1 must be >= 0 (0: off) and its tolerance in [0, pi) radians";
    return false;
  }
  if (!(predict_f1 >= 0.0 && std::isfinite(predict_f1)) || std::isinf(camera_yaw)) {
    if (error) *error = "prediction F1 must be >= 0 (0: off) and the camera yaw finite or NaN";
    return false;
  }
  if (!(look_back_f1 >= 0.0 && std::isfinite(look_back_f1))) {
    if (error) *error = "look-back F1 must be >= 0 (0: F1)";
    return false;
  }
  return gate.IsValid(error);
}

TrackerOptions paper_tracker_options() { return TrackerOptions{}; }

TrackerOptions recommended_tracker_options(double wheel_base) {
  TrackerOptions o;
  o.mutual = true;
  o.same_polarity = true;
  // Measured on the rendered tours (docs/theory/matching.md#the-rule-sets): track continuity with
  // the track model at 0.8 degree, F1 0.6 and 0.5 across a look-back gap.
  o.continuity_tolerance = deg2rad(0.8);  // used when the gate (odometry) is on
  o.continuity_model = TrackerOptions::ContinuityModel::kTrack;
  o.match.f1 = 0.6;
  o.look_back_f1 = 0.5;
  // Confirmed F1 (docs/theory/matching.md): with the extractor's finer peaks it brings
  // the corridor's false new entries under target at little cost in false matches.
  o.confirm_f1 = 1.05;
  o.confirm_tolerance = deg2rad(0.3);
  // Triangulated prediction and links by prediction up to the paper's F1
  // (docs/theory/matching.md#triangulated-prediction): they keep the tracks of near lines whose
  // descriptor changes beyond the tests between frames far apart.
  o.triangulate = true;
  o.predict_f1 = 1.05;
  if (wheel_base > 0.0) {
    o.gate.enabled = true;
    o.gate.wheel_base = wheel_base;
  }
  return o;
}

TrackerOptions recommended_dataset_tracker_options() {
  TrackerOptions o = recommended_tracker_options(0.0);
  o.gate.enabled = true;  // wheel_base: track_dataset's, from wheel0/sensor.yaml
  return o;
}

const char* to_string(LinkVerdict v) {
  switch (v) {
    case LinkVerdict::kLinked:
      return "linked";
    case LinkVerdict::kNoFrame:
      return "no-frame";
    case LinkVerdict::kNoCandidates:
      return "no-candidates";
    case LinkVerdict::kTest1:
      return "test1";
    case LinkVerdict::kTest2:
      return "test2";
    case LinkVerdict::kTest3:
      return "test3";
    case LinkVerdict::kLookBackF1:
      return "look-back-f1";
    case LinkVerdict::kMutual:
      return "mutual";
    case LinkVerdict::kClaimed:
      return "claimed";
    case LinkVerdict::kGate:
      return "gate";
    case LinkVerdict::kContinuity:
      return "continuity";
    case LinkVerdict::kFork:
      return "fork";
  }
  return "?";
}

std::string TrackerStats::BriefReport() const {
  std::ostringstream s;
  s << frames << " frames, " << lines << " lines: " << matched_previous
    << " matched in the previous frame, " << matched_look_back << " by look-back, " << new_tracks
    << " new tracks; rejected: test1 " << rejected_test1 << ", test2 " << rejected_test2
    << ", test3 " << rejected_test3 << ", mutual " << rejected_mutual << ", claimed "
    << rejected_claimed << ", odometry gate " << rejected_gate << ", continuity "
    << rejected_continuity << ", fork " << rejected_fork;
  if (linked_by_prediction > 0) s << "; linked by prediction " << linked_by_prediction;
  return s.str();
}

Tracker::Tracker(TrackerOptions options) : options_(options), matcher_(options.match) {
  // Options usually come from the user (flags, config): report, do not crash.
  std::string error;
  if (!options_.IsValid(&error)) throw InputError("tracker options: " + error);
  ring_.resize(static_cast<std::size_t>(options_.look_back));
}

Tracker::Slot& Tracker::slot_back(int k) {
  const std::int64_t frame = frame_count_ - k;
  assert(k >= 1 && k <= options_.look_back && frame >= 0);
  return ring_[static_cast<std::size_t>(frame % options_.look_back)];
}

const Tracker::Slot& Tracker::slot_back(int k) const {
  return const_cast<Tracker*>(this)->slot_back(k);
}

bool Tracker::track_claimed(std::int64_t id) const {
  return std::find(claimed_.begin(), claimed_.end(), id) != claimed_.end();
}

void Tracker::add_frame(const FrameFeatures& frame, std::vector<TrackAssignment>* out) {
  if (options_.gate.enabled) {
    throw std::invalid_argument("Tracker::add_frame: the odometry gate needs wheel increments");
  }
  add_frame(frame, WheelIncrement{}, out);
}

void Tracker::add_frame(const FrameFeatures& frame,
                        const WheelIncrement& since_previous,
                        std::vector<TrackAssignment>* out) {
  check_frame(frame);
  begin_frame(frame, since_previous, out);
  // Sec. 9.1: frame t-1 first, then further back for the lines still unmatched.
  const int held = static_cast<int>(std::min<std::int64_t>(frame_count_, options_.look_back));
  for (int k = 1; k <= held && !unmatched_.empty(); ++k) {
    if (slot_back(k).num_lines == 0) continue;
    const CandidateSearch c = search_candidates(frame, k);
    link_lines(frame, c, out);
  }
  link_by_prediction(frame, out);
  start_new_tracks(out);
  store_frame(frame, *out);
  ++stats_.frames;
  stats_.lines += static_cast<std::int64_t>(frame.lines.size());
}

void Tracker::check_frame(const FrameFeatures& frame) const {
  const int n = static_cast<int>(frame.lines.size());
  // Contract: one descriptor row per line, one width for the whole run.
  if (frame.descriptors.rows() != n) {
    throw std::invalid_argument("Tracker::add_frame: " + std::to_string(n) + " lines but " +
                                std::to_string(frame.descriptors.rows()) + " descriptor rows");
  }
  if (n > 0 && descriptor_width_ > 0 && frame.descriptors.cols() != descriptor_width_) {
    throw std::invalid_argument("Tracker::add_frame: descriptor width changed from " +
                                std::to_string(descriptor_width_) + " to " +
                                std::to_string(frame.descriptors.cols()));
  }
}

void Tracker::begin_frame(const FrameFeatures& frame,
                          const WheelIncrement& since_previous,
                          std::vector<TrackAssignment>* out) {
  const int n = static_cast<int>(frame.lines.size());
  if (n > 0) descriptor_width_ = frame.descriptors.cols();
  if (frame_count_ > 0 && options_.gate.enabled) {
    odometry_.add(since_previous, options_.gate.wheel_base);
  }
  out->assign(static_cast<std::size_t>(n), TrackAssignment{});
  claimed_.clear();
  if (options_.triangulate) {
    camera_yaw_ = std::isfinite(options_.camera_yaw) ? options_.camera_yaw : yaw_votes_.estimate();
  }
  if (static_cast<Eigen::Index>(unmatched_.capacity()) < n) {
    const auto cap = static_cast<std::size_t>(line_capacity(n));
    unmatched_.reserve(cap);
    rates_.reserve(cap);
    turn_rates_.reserve(cap);
    geometry_.reserve(cap);
    still_unmatched_.reserve(cap);
    claimed_.reserve(cap);
  }
  unmatched_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) unmatched_[static_cast<std::size_t>(i)] = i;
}

Tracker::CandidateSearch Tracker::search_candidates(const FrameFeatures& frame, int k) {
  CandidateSearch c;
  c.k = k;
  c.slot = &slot_back(k);
  // Query rows: the lines still unmatched (all of them for k = 1).
  c.num_queries = static_cast<int>(unmatched_.size());
  // All lines still in play (always so for k = 1): match the frame's own matrix, no copy.
  c.all_rows = c.num_queries == static_cast<int>(frame.lines.size());
  match_queries(frame, c);
  if (options_.gate.enabled) c.gate = make_bearing_gate(options_.gate, c.slot->odometry, odometry_);
  c.gate_restricts = options_.gate.enabled && options_.gate_candidates && c.gate.informative;
  c.restricted = c.gate_restricts || options_.same_polarity;
  if (c.restricted) retest_admissible(frame, c);
  return c;
}

void Tracker::match_queries(const FrameFeatures& frame, const CandidateSearch& c) {
  const auto candidates = c.slot->descriptors.topRows(c.slot->num_lines);
  const int nq = c.num_queries;
  if (c.all_rows) {
    matcher_.match(frame.descriptors, candidates, &results_);
    return;
  }
  if (query_.rows() < nq || query_.cols() != frame.descriptors.cols()) {
    query_.resize(line_capacity(std::max<Eigen::Index>(query_.rows(), nq)),
                  frame.descriptors.cols());
  }
  for (int q = 0; q < nq; ++q) {
    query_.row(q) = frame.descriptors.row(unmatched_[static_cast<std::size_t>(q)]);
  }
  matcher_.match(query_.topRows(nq), candidates, &results_);
}

bool Tracker::admissible(const FrameFeatures& frame, const CandidateSearch& c, int a, int j) const {
  const VerticalLine& l = frame.lines[static_cast<std::size_t>(a)];
  if (options_.same_polarity) {
    const int pj = c.slot->polarities[static_cast<std::size_t>(j)];
    if (l.polarity != 0 && pj != 0 && l.polarity != pj) return false;
  }
  return !c.gate_restricts ||
         c.gate.admits(c.slot->bearings[static_cast<std::size_t>(j)], l.bearing);
}

void Tracker::retest_admissible(const FrameFeatures& frame, const CandidateSearch& c) {
  const auto d = matcher_.last_distances();
  const int nc = static_cast<int>(c.slot->num_lines);
  for (int q = 0; q < c.num_queries; ++q) {
    const int line = unmatched_[static_cast<std::size_t>(q)];
    MatchResult& r = results_[static_cast<std::size_t>(q)];
    float best = std::numeric_limits<float>::infinity(), second = best;
    int best_j = -1, admitted = 0;
    for (int j = 0; j < nc; ++j) {
      if (!admissible(frame, c, line, j)) continue;
      ++admitted;
      const float v = d(q, j);
      if (v < best) {
        second = best;
        best = v;
        best_j = j;
      } else if (v < second) {
        second = v;
      }
    }
    if (admitted == 0) {
      if (r.accepted()) ++stats_.rejected_gate;
      r.best = -1;
      r.verdict = MatchVerdict::kNoCandidates;
      continue;
    }
    r.best = best_j;
    r.min_distance = best;
    r.second_distance = second;
    // N_B = all lines of the frame (test 2's mean over them); with one admitted candidate
    // the second distance is +inf and test 3 is vacuous.
    r.verdict = apply_match_tests(options_.match, nc, best, second, r.mean_distance);
  }
}

void Tracker::link_lines(const FrameFeatures& frame,
                         const CandidateSearch& c,
                         std::vector<TrackAssignment>* out) {
  still_unmatched_.clear();
  for (int q = 0; q < c.num_queries; ++q) {
    const int i = unmatched_[static_cast<std::size_t>(q)];
    const MatchResult& r = results_[static_cast<std::size_t>(q)];
    const LinkDecision d = decide_link(frame, c, i, r);
    if (c.k == 1) {
      TrackAssignment& a = (*out)[static_cast<std::size_t>(i)];
      a.previous_verdict = d.why;
      a.previous_candidate = r.best;
      a.previous_distance = r.min_distance;
    }
    if (!d.ok) {
      still_unmatched_.push_back(i);
      continue;
    }
    TrackAssignment& a = (*out)[static_cast<std::size_t>(i)];
    a.track_id = d.track_id;
    a.frames_back = c.k;
    a.matched_line = r.best;
    a.distance = r.min_distance;
    if (options_.mutual) claimed_.push_back(d.track_id);
    if (c.k == 1) {
      ++stats_.matched_previous;
    } else {
      ++stats_.matched_look_back;
    }
  }
  unmatched_.swap(still_unmatched_);
}

Tracker::LinkDecision Tracker::decide_link(const FrameFeatures& frame,
                                           const CandidateSearch& c,
                                           int line,
                                           const MatchResult& r) {
  LinkDecision d;
  d.ok = r.accepted();
  d.why = d.ok ? LinkVerdict::kLinked : LinkVerdict::kNoCandidates;
  if (d.ok && refused_by_look_back_f1(c.k, r)) {
    d.ok = false;
    d.why = LinkVerdict::kLookBackF1;
  }
  // Confirmed F1: a distance between F1 (or the look-back F1) and confirm_f1 is accepted
  // when tests 2 and 3 pass and the track's prediction confirms the line (checked below;
  // counted as a test 1 rejection only if that fails).
  const bool confirm = needs_confirmation(c, r, d.why);
  if (d.why == LinkVerdict::kLookBackF1 && !confirm) ++stats_.rejected_test1;
  if (const LinkVerdict v = match_test_verdict(r, confirm); v != LinkVerdict::kLinked) d.why = v;
  const LinkVerdict f1_verdict = d.why;  // what refuses the link if confirmation fails
  if (confirm) {
    d.ok = true;
    d.why = LinkVerdict::kLinked;
  }
  d.track_id = d.ok ? c.slot->track_ids[static_cast<std::size_t>(r.best)] : -1;
  // Our constraints, in turn: the first that refuses the link names the verdict.
  auto apply = [&d](LinkVerdict v) {
    if (v == LinkVerdict::kLinked) return;
    d.ok = false;
    d.why = v;
  };
  if (d.ok && options_.mutual) apply(mutual_verdict(frame, c, line, r, d.track_id));
  if (d.ok && options_.gate.enabled) apply(gate_verdict(frame, c, line, r));
  if (d.ok) apply(continuity_verdict(frame, c.k, line, r, confirm, f1_verdict));
  if (d.ok) apply(fork_verdict(c.k, d.track_id));
  return d;
}

bool Tracker::refused_by_look_back_f1(int k, const MatchResult& r) const {
  return k > 1 && options_.look_back_f1 > 0.0 && r.min_distance > options_.look_back_f1;
}

bool Tracker::needs_confirmation(const CandidateSearch& c,
                                 const MatchResult& r,
                                 LinkVerdict why) const {
  if (!(options_.confirm_f1 > 0.0 && r.best >= 0 && r.min_distance <= options_.confirm_f1 &&
        (why == LinkVerdict::kLookBackF1 || r.verdict == MatchVerdict::kFailedTest1))) {
    return false;
  }
  MatchOptions relaxed = options_.match;
  relaxed.f1 = options_.confirm_f1;
  const int nc = static_cast<int>(c.slot->num_lines);
  return apply_match_tests(relaxed, nc, r.min_distance, r.second_distance, r.mean_distance) ==
         MatchVerdict::kAccepted;
}

LinkVerdict Tracker::match_test_verdict(const MatchResult& r, bool needs_confirmation) {
  switch (r.verdict) {
    case MatchVerdict::kFailedTest1:
      if (!needs_confirmation) ++stats_.rejected_test1;
      return LinkVerdict::kTest1;
    case MatchVerdict::kFailedTest2:
      ++stats_.rejected_test2;
      return LinkVerdict::kTest2;
    case MatchVerdict::kFailedTest3:
      ++stats_.rejected_test3;
      return LinkVerdict::kTest3;
    default:
      return LinkVerdict::kLinked;
  }
}

LinkVerdict Tracker::mutual_verdict(const FrameFeatures& frame,
                                    const CandidateSearch& c,
                                    int line,
                                    const MatchResult& r,
                                    std::int64_t id) {
  // Reverse direction first (so that the reason does not depend on the order in which
  // lines are processed): the nearest line of the new frame to B_best must be A_i.
  if (nearest_new_line(frame, c, r.best) != line) {
    ++stats_.rejected_mutual;
    return LinkVerdict::kMutual;
  }
  if (track_claimed(id)) {
    // One line per track and frame: taken by a line matched in a more recent frame.
    ++stats_.rejected_claimed;
    return LinkVerdict::kClaimed;
  }
  return LinkVerdict::kLinked;
}

int Tracker::nearest_new_line(const FrameFeatures& frame, const CandidateSearch& c, int j) const {
  // Computed for the accepted candidate only (n dot products), ties to lowest index.
  const int n = static_cast<int>(frame.lines.size());
  int nearest = -1;
  if (c.restricted) {
    // Among the lines of the new frame admissible for B_best.
    const auto b = c.slot->descriptors.row(j);
    float nearest_sq = std::numeric_limits<float>::infinity();
    for (int a = 0; a < n; ++a) {
      if (!admissible(frame, c, a, j)) continue;
      const float sq = descriptor_distance_sq(options_.match, frame.descriptors.row(a), b);
      if (sq < nearest_sq) {
        nearest_sq = sq;
        nearest = a;
      }
    }
  } else if (c.all_rows) {
    // The whole column of distances to B_best is at hand (row q is line q).
    Eigen::Index idx = 0;
    matcher_.last_distances().col(j).minCoeff(&idx);
    nearest = static_cast<int>(idx);
  } else {
    const auto b = c.slot->descriptors.row(j);
    float nearest_sq = std::numeric_limits<float>::infinity();
    for (int a = 0; a < n; ++a) {
      const float sq = descriptor_distance_sq(options_.match, frame.descriptors.row(a), b);
      if (sq < nearest_sq) {
        nearest_sq = sq;
        nearest = a;
      }
    }
  }
  return nearest;
}

LinkVerdict Tracker::gate_verdict(const FrameFeatures& frame,
                                  const CandidateSearch& c,
                                  int line,
                                  const MatchResult& r) {
  if (c.gate.admits(c.slot->bearings[static_cast<std::size_t>(r.best)],
                    frame.lines[static_cast<std::size_t>(line)].bearing)) {
    return LinkVerdict::kLinked;
  }
  ++stats_.rejected_gate;
  return LinkVerdict::kGate;
}

LinkVerdict Tracker::continuity_verdict(const FrameFeatures& frame,
                                        int k,
                                        int line,
                                        const MatchResult& r,
                                        bool needs_confirmation,
                                        LinkVerdict f1_verdict) {
  const bool continuity = options_.gate.enabled && options_.continuity_tolerance > 0.0;
  if (!continuity && !needs_confirmation) return LinkVerdict::kLinked;
  // One prediction of the track serves both checks; confirmation needs continuity.
  const TrackPrediction p = continuity ? predict_track(k, r.best) : TrackPrediction{};
  if (continuity && !continues_track(p, frame.lines[static_cast<std::size_t>(line)].bearing)) {
    ++stats_.rejected_continuity;
    return LinkVerdict::kContinuity;
  }
  if (needs_confirmation && !(continuity && confirms_track(p, frame, line))) {
    ++stats_.rejected_test1;
    return f1_verdict;
  }
  return LinkVerdict::kLinked;
}

LinkVerdict Tracker::fork_verdict(int k, std::int64_t id) {
  if (k > 1 && options_.heads_only && observed_since(id, k)) {
    ++stats_.rejected_fork;
    return LinkVerdict::kFork;
  }
  return LinkVerdict::kLinked;
}

void Tracker::start_new_tracks(std::vector<TrackAssignment>* out) {
  // Sec. 9.1: no correspondence in any of the frames looked at: a new track.
  for (int i : unmatched_) {
    TrackAssignment& a = (*out)[static_cast<std::size_t>(i)];
    a.track_id = next_track_id_++;
    ++stats_.new_tracks;
  }
}

bool Tracker::observed_since(std::int64_t id, int k) {
  for (int m = 1; m < k; ++m) {
    const Slot& s = slot_back(m);
    const auto end = s.track_ids.begin() + s.num_lines;
    if (std::find(s.track_ids.begin(), end, id) != end) return true;
  }
  return false;
}

void Tracker::store_frame(const FrameFeatures& frame, const std::vector<TrackAssignment>& out) {
  const int n = static_cast<int>(frame.lines.size());
  measure_track_rates(frame, out);
  measure_track_geometry(frame, out);
  // The slot of frame t replaces that of frame t - look_back, which is no longer needed.
  Slot& slot = ring_[static_cast<std::size_t>(frame_count_ % options_.look_back)];
  const Eigen::Index cols = frame.descriptors.cols();
  if (slot.descriptors.rows() < n || slot.descriptors.cols() != cols) {
    slot.descriptors.resize(line_capacity(std::max<Eigen::Index>(slot.descriptors.rows(), n)),
                            cols);
    slot.bearings.reserve(static_cast<std::size_t>(slot.descriptors.rows()));
    slot.polarities.reserve(static_cast<std::size_t>(slot.descriptors.rows()));
    slot.parallax_rates.reserve(static_cast<std::size_t>(slot.descriptors.rows()));
    slot.turn_rates.reserve(static_cast<std::size_t>(slot.descriptors.rows()));
    slot.geometry.reserve(static_cast<std::size_t>(slot.descriptors.rows()));
    slot.track_ids.reserve(static_cast<std::size_t>(slot.descriptors.rows()));
  }
  if (n > 0) slot.descriptors.topRows(n) = frame.descriptors;
  slot.bearings.resize(static_cast<std::size_t>(n));
  slot.polarities.resize(static_cast<std::size_t>(n));
  slot.parallax_rates.assign(rates_.begin(), rates_.end());
  slot.turn_rates.assign(turn_rates_.begin(), turn_rates_.end());
  slot.geometry.assign(geometry_.begin(), geometry_.end());
  slot.track_ids.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    slot.bearings[static_cast<std::size_t>(i)] = frame.lines[static_cast<std::size_t>(i)].bearing;
    slot.polarities[static_cast<std::size_t>(i)] =
        frame.lines[static_cast<std::size_t>(i)].polarity;
    slot.track_ids[static_cast<std::size_t>(i)] = out[static_cast<std::size_t>(i)].track_id;
  }
  slot.num_lines = n;
  slot.odometry = odometry_;
  ++frame_count_;
}

}  // namespace omnivert
