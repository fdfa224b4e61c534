#pragma once
// The descriptor study of the paper's Sec. 6 on a dataset with ground truth, and the
// baselines ZNCC (Sec. 5's rectangular pattern) and LBD (OpenCV line_descriptor) on the same
// frames. docs/study.md describes the protocol and gives the numbers.
//
// Ground truth (Sec. 6.0.1): the paper labelled the extracted lines of 850 images by hand and
// matched each line against every image where it appears, over baselines up to 2 m. Here:
//  - lines are extracted by the pipeline (Sec. 2) and each is associated to the ground-truth
//    line of its frame with the nearest bearing, within `association_tolerance` (1 degree, as
//    in tracking_eval); lines with none (clutter) or with two candidates (ambiguous) keep
//    line_id -1: they stay as candidates but are never queries;
//  - two frames are compared when the robot positions are at most `max_baseline` (2 m) apart;
//  - a query is an associated line of frame k; a candidate set is all lines of frame l (a
//    frame pair), or of all frames within the baseline (the "database" of Figs. 13-15).
// The nearest candidate is a correct match when it carries the query's line_id. A query whose
// line does not appear among the candidates can only give a false match; it counts in the
// match distributions (Figs. 16-18) and in precision, and not in recall or in the % correct
// nearest-neighbour matches (which, as the paper's, asks: when the line is there, is the
// nearest descriptor the right one?).

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/describe/feature_pipeline.hpp"

namespace omnivert::eval {

struct StudyOptions {
  double max_baseline = 2.0;                    // metres between robot positions
  double association_tolerance = deg2rad(1.0);  // radians
  int frame_stride = 1;                         // use every n-th image
  int max_frames = 0;                           // 0: all (after the stride)
  FeaturePipelineOptions pipeline;              // extraction (the descriptor is varied later)
  bool progress = true;
  // Threads reading images and extracting lines and descriptors (0: every core); the mirror
  // circle is located frame after frame, so the set is the same, bit for bit, for every count.
  int threads = 0;
};

struct StudyLine {
  int line_id = -1;  // ground-truth id, -1: unassociated or ambiguous
  double image_angle = 0.0;
  double bearing = 0.0;
  double r_inner = 0.0, r_outer = 0.0;
};

struct StudyFrame {
  std::size_t index = 0;  // image index in the dataset
  cv::Mat1b image;
  MirrorCircle circle;
  std::vector<StudyLine> lines;
  double x = 0.0, y = 0.0;  // robot position (ground truth)
};

struct StudySet {
  std::vector<StudyFrame> frames;
  std::vector<std::vector<int>> neighbours;  // frames within max_baseline, without itself
  int bearing_sign = 1;
  std::size_t lines() const;
  std::size_t associated() const;
  std::size_t frame_pairs() const;  // ordered pairs (k, l), l in neighbours[k]
};

// Reads, extracts and associates. Throws InputError when the dataset has no ground-truth
// lines or poses, or when no frame has an associated line.
StudySet load_study_set(const dataset::Dataset& data, const StudyOptions& options);

// Candidate distances of one method: for a frame pair (k, l), the n_k x n_l matrix of
// distances between the lines of k and the lines of l (the method's own lines).
struct MethodFeatures {
  std::string name;
  std::vector<std::vector<int>> ids;  // per frame: line_id of each line (-1: not a query)
  std::function<cv::Mat1f(int k, int l)> distances;
};

// Our descriptor (Sec. 3) at the study's lines, with given options, on the frames with
// additive Gaussian noise of `noise_sigma` grey levels (0: none; Sec. 6.0.3), seeded.
MethodFeatures describe_ours(const StudySet& set,
                             const DescriptorOptions& options,
                             double noise_sigma = 0.0,
                             std::uint64_t seed = 1);

// ZNCC of the rectangular pattern of width 2 r_a in each frame's panorama (Sec. 5); the
// distance is 1 - ZNCC.
MethodFeatures describe_zncc(const StudySet& set);

struct LbdOptions {
  // EDLines segments (BinaryDescriptor::detect) or LSD (LSDDetector).
  bool use_lsd = false;
  // A segment is near-radial when its direction is within this of the radial direction at
  // its midpoint, [rad].
  double max_radial_angle = deg2rad(3.0);
  // ... and its length at least this fraction of R_max - R_min, and its midpoint in the annulus.
  double min_length_fraction = 0.15;
};

// OpenCV's LBD (line_descriptor::BinaryDescriptor), Hamming distances from
// BinaryDescriptorMatcher. Segments are associated to the ground truth by the bearing of
// their midpoint (same tolerance as our lines); unassociated segments stay as candidates.
MethodFeatures describe_lbd_segments(const StudySet& set,
                                     const dataset::Dataset& data,
                                     const LbdOptions& options,
                                     double association_tolerance);

// LBD computed on our radial lines (KeyLines from r_inner to r_outer): the descriptor alone,
// on exactly our line set.
MethodFeatures describe_lbd_on_our_lines(const StudySet& set);

// One query against one frame's candidates.
struct MatchRecord {
  int query_frame = 0, candidate_frame = 0;
  int query_id = -1, nearest_id = -1;
  double nearest = 0.0, second = 0.0, mean = 0.0;  // distances (second: +inf with 1 candidate)
  int candidates = 0;
  bool has_true = false;  // the query's line is among the candidates
  bool correct() const { return nearest_id == query_id; }
};

// Every query of every ordered frame pair (k, l), l in neighbours[k], with >= 1 candidate.
std::vector<MatchRecord> match_frame_pairs(const StudySet& set, const MethodFeatures& method);

struct NearestNeighbourScore {
  std::int64_t queries = 0;  // queries whose line is in the database
  std::int64_t correct = 0;
  double percent() const { return queries > 0 ? 100.0 * correct / queries : 0.0; }
};

// Figs. 13-15: per query, the nearest line over the database of all frames within the
// baseline; correct when it is the same world line.
NearestNeighbourScore nearest_neighbour_score(const StudySet& set, const MethodFeatures& method);

// The same question on single frame pairs, harder than the database (where a frame 4 cm
// away usually holds the line): over records whose line is among the candidates and whose
// frames are between min_baseline and max_baseline apart [m].
NearestNeighbourScore pair_nearest_score(
    const StudySet& set,
    const std::vector<MatchRecord>& records,
    double min_baseline = 0.0,
    double max_baseline = std::numeric_limits<double>::infinity());

// The three matching rules (Sec. 4, eq. 8-10) as distributions (Figs. 16-18).
struct RuleShares {
  double threshold = 0.0;
  double false_removed = 0.0;  // share of incorrect nearest matches the rule rejects
  double correct_lost = 0.0;   // share of correct nearest matches it rejects
  std::int64_t correct = 0, incorrect = 0;
};
// rule 1: nearest distance; rule 2: nearest / mean; rule 3: nearest / second.
double rule_value(const MatchRecord& r, int rule);
RuleShares rule_shares(const std::vector<MatchRecord>& records, int rule, double threshold);

// Precision and recall of "accept the nearest when nearest / second <= t", swept over t.
// recall = accepted correct / queries with their line among the candidates;
// precision = accepted correct / accepted.
struct PrPoint {
  double threshold = 0.0, precision = 0.0, recall = 0.0;
};
std::vector<PrPoint> precision_recall(const std::vector<MatchRecord>& records,
                                      int max_points = 200);
// The best precision among operating points with recall >= r (NaN if none reaches r).
double precision_at_recall(const std::vector<PrPoint>& curve, double r);
// Area under the precision-recall curve (step-wise), over the recall reached.
double average_precision(const std::vector<PrPoint>& curve);

// Precision and recall of the three rules together (our matcher's decision) at F1, F2, F3.
PrPoint rules_operating_point(const std::vector<MatchRecord>& records,
                              double f1,
                              double f2,
                              double f3);

}  // namespace omnivert::eval
