#pragma once
// Which bearings belong together, decided on a solved batch problem (refinement and start-up
// window): bearings left out where lines cross (the crossing guard), pieces of one line
// joined, tracks split where they slipped onto a neighbouring line.

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "calib/batch_point.hpp"
#include "calib/batch_problem.hpp"
#include "calib/factor_paths.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib::internal {

// The frames of each track's bearings in the problem, in order.
std::map<int, std::vector<int>> track_frames(const Built& b);

// Whether two sorted frame lists have a frame in common.
bool share_a_frame(const std::vector<int>& a, const std::vector<int>& c);

// Whether tracks a and c are one line: the Wald statistic of "one feature point" (f_a = f_c)
// at the current solution, d^T Cov(d)^-1 d with d = f_a - f_c and Cov(d) from the inverse of
// the whole problem's information (poses and extrinsics free: held fixed, the poses' own
// uncertainty made pieces of one line look apart, statistics up to 370 at 0.025 degree), is
// below `chi2` (chi-square, 2 degrees of freedom). The factorisation is made once per call
// of reject_crossings (`cache`), the columns of each feature once.
struct FeatureCovariance {
  FeatureCovariance() = default;
  // `paths` refers to `ldlt`: neither copied nor moved (a moved one would refer to the old).
  FeatureCovariance(const FeatureCovariance&) = delete;
  FeatureCovariance& operator=(const FeatureCovariance&) = delete;

  bool ready = false, ok = false;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;  // P F P^T = L D L^T
  std::map<int, int> column;                                // track id -> first column
  // Track id -> L^-1 P E (E: its two columns of the identity) on the rows it reaches.
  // Cov(f_a - f_c) = (Y_a - Y_c)^T D^-1 (Y_a - Y_c).
  std::unique_ptr<FactorPaths> paths;  // on `ldlt`
  std::map<int, FactorPaths::Forward> solved;
};

// The statistic itself (infinity when it cannot be computed).
double one_line_statistic(Built* b, int a, int c, FeatureCovariance* cache);

bool one_line(Built* b, int a, int c, double chi2, FeatureCovariance* cache);

// The crossing guard (CalibrationOptions::association.crossing_guard): removes the bearings of a
// feature at the frames where another feature, over its track's span (first to last bearing)
// widened by `margin` frames on each side, is predicted within `guard` of it as seen from the
// camera, at the current solution. (The widening: a track often starts or ends where its line met
// another, its detections given to the other track meanwhile; the tracker bridges gaps of
// max_missed_frames, the margin used.) There the extractor
// sees one line where there are two: the detection is pulled towards the other line, or
// belongs to it (a track pulled by up to 0.19 degree by lines passing within 1 degree is then
// split by the slip test although it never left its line;
// docs/theory/association.md#lines-that-cross;
// CrossingGuard.MergedDetectionsAreLeftOutAndDoNotMoveTheEstimate). The bearings are not
// independent Gaussian errors about the line there, which is what eq. (30) assumes. Then the
// features left with fewer than `min_bearings` bearings go (drop_unobserved_features). Returns how
// many bearings; their keys are added to b->guarded. A line the tracker lost and found again under
// a new id is not a crossing either: two tracks that never share a frame and whose bearings one
// point explains (one_line) are one line. Otherwise a track's pieces guard each other over the
// margin, and with tracks broken every ~10 frames the guard leaves out most bearings
// (CrossingGuard.PiecesOfOneLineDoNotGuardEachOther; synthetic paper run, break probability 0.1:
// 950 of 1140 in the filter, most features of the refinement).
int reject_crossings(Built* b,
                     double guard,
                     int margin,
                     int min_bearings,
                     const std::map<int, int>& origin,
                     double merge_chi2);

// The likelihood-ratio statistic of "one point" for tracks a and c with the poses and the
// extrinsics held at the current solution: the least squares cost of all their bearings
// about the one point that fits them best (Gauss-Newton from each of the two points) minus
// their costs about their own points (the solution's, optimal there). About chi-square(2)
// under one point. Unlike the Wald test it keeps its power when a piece is too short to
// place its point: three bearings over three frames have no depth, their point's covariance
// is enormous along the ray, and the Wald statistic of a piece of another line can come out
// 0.00 (PiecesOfOneLine.AreJoinedOnlyWithTheirOwnLine).
double one_point_statistic(Built* b, const std::vector<std::size_t>& blocks, int a, int c);

// Pieces of one line (CalibrationOptions::association.join_pieces): a tracker that loses a line and
// finds it again gives it a new id, and the batch then has two features where there is one point.
// Each piece is estimated from its own few bearings, from little parallax; with tracks broken every
// ~10 frames (synthetic paper runs, calib_monte_carlo
// --break 0.1) the refinement's NEES is 4.1 over 100 runs unjoined where the unbroken tracks
// give 2.9 (docs/theory/association.md#pieces-of-one-line). Candidates: two tracks that never share
// a frame, at most `max_gap` frames apart (or interleaved: a chain of joins can skip a piece, which
// a later round then joins). They are one line when one point explains both, by two tests that must
// agree: one_point_statistic (poses held; keeps its power for a piece without depth) and the
// Wald statistic of one_line (the whole problem's covariance; poses free, so long pieces of
// one line are not held apart by pose errors: 7% of them failed the first test alone at
// chi-square(2), 0.999), each below `chi2`. Each track joins at most one successor and one
// predecessor per round, the pairs with the smallest first statistic first (each track in at
// most one join per round: 100 synthetic runs broken every ~10 frames, refinement NEES 4.25
// against 3.17). Returns (a, c) pairs, a the piece seen first: c's bearings are a's line.
std::vector<TrackJoin> find_merges(Built* b, int max_gap, double chi2);

// Track splitting (CalibrationOptions::association.split_chi2). A track that slipped onto a
// neighbouring line (a door leaf 6 cm inside its frame) is two features glued together: from the
// frame of the slip on, its bearings follow another point. For each track and each split frame j,
// the likelihood-ratio statistic of "two features, before and after j" against "one feature" with
// poses and extrinsics held at the current solution, linearised there: with the whitened residuals
// r_i and their Jacobians J_i (1x2) on the feature point, each segment's best feature step reduces
// the squared residuals by g^T H^-1 g (g = sum J_i^T r_i, H = sum J_i^T J_i), computed for every j
// at once from prefix sums. Under no slip the statistic at a fixed j is chi-square with 2 degrees
// of freedom. A track whose best statistic exceeds the threshold is split there, and each part
// again where its own statistic does (from the same linearisation). Returns (track id, first
// frame of a new part), sorted.
std::vector<std::pair<int, int>> find_splits(const Built& b, const AssociationOptions& split);

// One round of track splitting: `found` (find_splits, ids of `current`) is added to `splits`
// (tracker's ids, frames of the runs), the run is split again from `original` (split_tracks),
// and `at`, keyed by the ids of `current`, is re-keyed to the new run's ids, each new part
// starting where the part it came from was. Returns the new run; `origin` receives new id ->
// tracker's id. (The refinement and the filter's window.)
CalibrationRun split_round(const CalibrationRun& original,
                           const CalibrationRun& current,
                           const std::vector<std::pair<int, int>>& found,
                           std::vector<TrackSplit>* splits,
                           std::map<int, int>* origin,
                           BatchPoint* at);

// Rounds of joining the pieces of one line (refinement and window), each on the problem
// solved again after the last.
inline constexpr int kMergeRounds = 10;

// One round of joining (find_merges) on the solved problem `b`: `run` renamed (join_tracks),
// `at` the solution with the joined pieces' points dropped (each line starts at its first
// piece's), the joins appended to *joins. Returns false when nothing joins.
bool merge_round(Built* b,
                 const CalibrationOptions& options,
                 CalibrationRun* run,
                 BatchPoint* at,
                 std::vector<TrackJoin>* joins);

// CalibrationOptions::noise.track_bias_sigma: which bearings belong together (lines that cross,
// outliers, pieces of one line joined, tracks split where they slipped) is decided under the white
// model whose sigma is a bearing's whole error, sqrt(bearing_sigma^2 + track_bias_sigma^2);
// the estimate and its covariance under the model with the per-track bias, on the bearings
// those decisions kept (final_with_bias). With the bias in the decisions, a slip onto a
// neighbouring line is partly taken up by the slipped track's bias and left in: from pixels,
// office zigzag at 0.018 + 0.016 degree, 6 of 100 filter runs ended 0.25-0.36 degree off
// (NEES 10-24).
CalibrationOptions association_options(const CalibrationOptions& options);

// The problem of `b`'s bearings (on `run`, the run its ids are of) with the per-track bias,
// from b's solution. `min_track_length`: of the problem that made the decisions.
Built final_with_bias(const CalibrationRun& run,
                      const Built& b,
                      const CalibrationOptions& options,
                      bool robust,
                      int min_track_length);

// The association loop of a batch estimator (refine_batch, the start-up window), on its
// solved problem: bearings left out where lines cross (reject_crossings), features that
// collapsed onto the camera dropped, outliers rejected at the filter's gate (up to three
// rounds), each step followed by a solve; then rounds of joining the pieces of one line
// (merge_round) and rounds of splitting the tracks that slipped (find_splits, split_round),
// each on the problem rebuilt from the last solution, solved, and judged again as above.
struct AssociationSetup {
  // crossing_guard, max_missed_frames, gate_probability, min_feature_range.
  const CalibrationOptions* options = nullptr;
  // A feature keeps at least this many bearings: 2 (two rays fix a point), 1 with a prior on
  // its depth (the window).
  int min_bearings = 2;
  bool join_pieces = true;
  // split_chi2 (0: no splitting), split_rounds, split_min_bearings, split_keep_fraction.
  AssociationOptions split;
  // The tracker's id of each renamed id of the run given (the window's parts after a gap).
  std::map<int, int> base_origin;
  // Whether a problem left without features ends the loop (AssociationEnd); otherwise it is
  // solved on.
  bool stop_when_empty = false;
  // After a round joined or split tracks, every bearing is judged before the first solve of
  // the new problem, at the last solution with the joined and split tracks' points placed from
  // their own bearings (it then starts clean, without the outliers found before, and one
  // global solve per round is saved); false: every bearing back in for that solve.
  bool judge_before_solving = false;
  // The problem of a renamed run from a starting point (the estimator's own build), and its
  // solve.
  std::function<Built(const CalibrationRun&, const BatchPoint&)> rebuild;
  std::function<void(Built*)> solve;
  // Each round reported as it starts (CalibrationOptions::progress; the refinement's, not the
  // window's): "refinement: joining pieces" and "refinement: splitting tracks", the round.
  std::function<void(const std::string&, std::size_t, std::size_t)> progress;
};

// The points of the tracks in `changed` placed at `at`'s poses and extrinsics: each solved
// from its own bearings alone (setup.rebuild's problem of those tracks, everything but their
// points held; at most 50 iterations), replacing theirs in `at`. A joined track starts at its
// first piece's point and a split part at the point of the track it came from (merge_round,
// split_round), which lay between two lines; placed, each is where its own bearings put it
// (AssociationSetup::judge_before_solving).
void place_changed(const CalibrationRun& run,
                   const std::set<int>& changed,
                   const AssociationSetup& setup,
                   BatchPoint* at);

// What the association decided.
struct Association {
  CalibrationRun merged;  // the run with the joined pieces under their line's first id
  CalibrationRun split;   // `merged` with the slipped tracks split (when splits is not empty)
  std::vector<TrackJoin> merges;   // (earlier piece's id, joined piece's id)
  std::vector<TrackSplit> splits;  // (id in `merged`, first frame of the new part)
  std::map<int, int> origin;       // id of a split part -> its id in `merged`
  int num_splits = 0;
  int num_rejected = 0;  // outliers rejected by the last rejection
  // The run the solved problem's ids are of.
  const CalibrationRun& solved() const { return splits.empty() ? merged : split; }
};

// The tracker's id of each renamed id: `origin` (split parts) composed with `base` (ids of
// the run given).
std::map<int, int> tracker_ids(const std::map<int, int>& base, const std::map<int, int>& origin);

enum class AssociationEnd {
  kDone,
  kNoTrack,      // a rebuilt problem had no feature (stop_when_empty)
  kNoTrackLeft,  // the rejections left no feature (stop_when_empty)
};
// The association loop on `b`, a solved problem of `run`; *b is the last problem solved.
AssociationEnd associate(Built* b,
                         const CalibrationRun& run,
                         const AssociationSetup& setup,
                         Association* out);

}  // namespace omnivert::calib::internal
