#pragma once
// Tracking evaluation against ground truth: the paper's Table 3 (Sec. 9.1), detection recall
// of long lines and bearing error. The rules (docs/tracking.md#evaluation):
//
//  1. Association: a detection is associated to the ground-truth line of the same frame whose
//     bearing is nearest (wrapped difference), if that difference is at most 1 degree
//     (association_tolerance); otherwise it is unassociated (clutter, or a bearing error above
//     the tolerance).
//  2. A match (link) joins a detection to its predecessor in the same track: the detection of
//     that track in `matched_frame` when the row says so (nearest bearing if the track has
//     several there), otherwise the track's latest detection in an earlier frame. The first
//     detection of a track id is a new entry, not a match.
//  3. A link joins two detections of different world lines (a false match) when no single
//     world line explains both. Each detection has the set of world lines within the
//     tolerance (usually one; several where true lines are closer than 1 degree: crossings,
//     lines far ahead). Along each track an identity set is carried: a new entry starts with
//     its set; a link is correct when the predecessor's identity set meets the detection's
//     set (the identity becomes the intersection), a false match when they are disjoint (the
//     identity restarts from the detection's set), and unverified when either set is empty
//     (an unassociated end). Without ambiguity this is exactly "both ends associated to the
//     same / different world lines"; with it, two tracks swapping at a crossing count one
//     false match each, at the link where their lines separate.
//  4. A new entry is a false new entry when its world line was detected (some detection
//     associated to it) in one of the previous `look_back` frames (20).
//  5. Rates are fractions of (matches + false new entries): correct + false matches + false
//     new entries + unverified = 100%. Links count in the interval of their later detection,
//     new entries in the interval of their frame; intervals of `interval` frames (200).
//  6. Long-line recall: over ground-truth rows with r_outer - r_inner >= long_line_fraction
//     (60%) of the annulus R_max - R_min, the fraction with a detection associated to them.
//  7. Bearing RMS: over associated detections, of wrap(detected - true); it is truncated by
//     the association tolerance, so read it together with the association rate.
//  8. Track purity: per track, the world line of most of its associated detections; the
//     associated detections on other lines are "off the majority line". A track that slips
//     onto a close line (a door leaf inside its frame) costs one false match by rule 3 but
//     every detection after the slip here, and it is these that bias a calibration.
//
// Ground-truth rows come from ground_truth/lines.csv (read by the dataset stage).

#include <cstdint>
#include <string>
#include <vector>

#include "omnivert/core/angles.hpp"
#include "omnivert/match/tracks_io.hpp"

namespace omnivert::eval {

// One ground-truth vertical line visible in one frame.
struct GroundTruthLine {
  std::int64_t frame = 0;    // 0-based image index
  std::int64_t line_id = 0;  // world line id (stable over the run)
  double bearing = 0.0;      // true camera bearing, radians
  double r_inner = 0.0;      // radial extent in the image, pixels
  double r_outer = 0.0;
};

// A side of a moving occluder in one frame (ground_truth/occluders.csv): a vertical edge of no
// world line.
struct OccluderBearing {
  std::int64_t frame = 0;
  double bearing = 0.0;  // camera bearing, radians
};

struct TrackingEvalOptions {
  double association_tolerance = deg2rad(1.0);  // radians
  int look_back = 20;                           // frames, for false new entries
  int interval = 200;                           // frames per table row (Table 3)
  double annulus_r_min = 0.0;                   // R_min, pixels (required)
  double annulus_r_max = 0.0;                   // R_max, pixels (required, > R_min)
  double long_line_fraction = 0.6;              // of R_max - R_min
  // Number of frames of the dataset (for the table's last interval); <= 0: the largest frame
  // index seen in tracks or ground truth, plus one.
  std::int64_t num_frames = 0;

  bool IsValid(std::string* error) const;
};

// One row of Table 3 (and the total).
struct TrackingCounts {
  std::int64_t first_frame = 0;
  std::int64_t end_frame = 0;  // exclusive
  std::int64_t matches = 0;    // links between consecutive detections of a track
  std::int64_t correct = 0;
  std::int64_t false_matches = 0;
  std::int64_t unverified = 0;  // links with an unassociated end
  std::int64_t new_entries = 0;
  std::int64_t false_new_entries = 0;

  std::int64_t denominator() const { return matches + false_new_entries; }
  double percent(std::int64_t n) const {
    return denominator() > 0 ? 100.0 * static_cast<double>(n) / denominator() : 0.0;
  }
  double percent_correct() const { return percent(correct); }
  double percent_false_matches() const { return percent(false_matches); }
  double percent_false_new_entries() const { return percent(false_new_entries); }
  double percent_unverified() const { return percent(unverified); }
};

struct TrackingEvaluation {
  std::vector<TrackingCounts> intervals;
  TrackingCounts total;
  std::int64_t detections = 0;
  std::int64_t associated_detections = 0;
  std::int64_t ambiguous_detections = 0;  // several true lines within the tolerance
  std::int64_t duplicate_ids = 0;         // detections sharing a track id with another in one frame
  std::int64_t long_lines = 0;            // ground-truth rows of long lines
  std::int64_t long_lines_detected = 0;
  double long_line_recall() const {
    return long_lines > 0 ? static_cast<double>(long_lines_detected) / long_lines : 0.0;
  }
  double bearing_rms = 0.0;                  // radians, over associated detections
  std::int64_t off_majority_detections = 0;  // rule 8
  // Rule 9: detections on an occluder's side (nearer to it than to every true line, within the
  // tolerance), left out with the links and new tracks they make.
  std::int64_t occluder_detections = 0;
  std::int64_t occluder_links = 0;
  std::int64_t occluder_new_tracks = 0;
};

// Evaluates `tracks` against `ground_truth`. Throws InputError with the reason when the
// options are not valid (e.g. the annulus is missing).
TrackingEvaluation evaluate_tracking(const std::vector<TrackRow>& tracks,
                                     const std::vector<GroundTruthLine>& ground_truth,
                                     const TrackingEvalOptions& options,
                                     const std::vector<OccluderBearing>& occluders = {});

// The paper's Table 3 as text, with the total, the recall of long lines and the bearing RMS.
std::string format_tracking_table(const TrackingEvaluation& evaluation,
                                  const std::string& title = "Recognition rate (Table 3)");

}  // namespace omnivert::eval
