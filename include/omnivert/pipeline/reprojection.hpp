#pragma once
// The check of a calibration by eye, paper Sec. 9.2, Figs. 23 and 26: reference points whose
// position on the robot is known without the camera (a laser scan, the corners of a map) are
// carried into the camera with a mounting (phi, rho, psi) and drawn on the image at their
// bearings; the scan's corners, where vertical edges stand, should meet the extracted vertical
// lines. The number behind the picture is the bearing offset between each corner and the
// nearest extracted line of its frame, the median over the run (docs/outputs.md#reprojection).
//
// References, one of (docs/calibration.md#checking-the-result-by-eye):
//   laser    laser0/ (dataset/laser.hpp): for each image the scan nearest in time (within
//            max_scan_gap_s), moved to the image's time by the odometry between the two
//            (eq. 14 over every wheel sample between), its corners found in the scan;
//   map      ground_truth/edges.csv with poses.csv and lines.csv of a simulated dataset: the
//            world's vertical edges visible in each frame, at the true robot pose;
//   corners  a user's CSV of vertical corners in the robot frame of the first image
//            (dataset::load_corners_csv), carried to each image by dead reckoning.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "omnivert/calib/types.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/dataset/laser.hpp"
#include "omnivert/describe/feature_pipeline.hpp"

namespace omnivert::pipeline {

// ---- geometry ----

// (x, y, theta) of a frame in another.
using Pose2d = Eigen::Vector3d;
// A point given in the frame `pose` into the frame that pose is expressed in.
Eigen::Vector2d transform_point(const Pose2d& pose, const Eigen::Vector2d& p);
Pose2d compose(const Pose2d& a, const Pose2d& b);
Pose2d inverse(const Pose2d& a);
// Camera bearing of a point of the robot frame for a mounting (docs/theory/conventions.md):
// atan2 in the camera frame, whose origin is rho (cos phi, sin phi) and x-axis at phi + psi.
double camera_bearing(const calib::Extrinsics& mounting, const Eigen::Vector2d& p_robot);
// The robot's pose at odometry time t_b in its frame at t_a: eq. (14) over every wheel sample
// between (calib::compose_wheel_steps); both times inside the wheel data.
Pose2d odometry_between(const dataset::Dataset& data, std::int64_t t_a, std::int64_t t_b);

// Where vertical edges stand in a 2D scan: where two straight pieces of the scan meet at an
// angle (the intersection of their fitted lines: a corner), and where a piece ends in front of
// a jump to a farther surface or to no return (an end: the end of a wall, the side of a box,
// located only to within half a ray's spacing, the scanner's resolution).
struct CornerOptions {
  double split_tolerance = 0.02;  // split-and-merge: a piece is straight to this [m]
  int min_points = 6;             // a straight piece has at least this many points
  double min_length = 0.15;       // and is at least this long [m]
  double min_angle_deg = 30.0;    // two pieces meet at a corner when they turn by this much
  double jump = 0.12;             // consecutive points farther apart than this + 3 % of the
                                  // range are on different surfaces [m]
};
// Valid points of a scan, in the scanner frame.
std::vector<Eigen::Vector2d> scan_points(const dataset::LaserScan& scan);
// Corners of a scan, in the scanner frame; its ends into `ends`, or among the corners when
// `ends` is null.
std::vector<Eigen::Vector2d> scan_corners(const dataset::LaserScan& scan,
                                          const CornerOptions& options = {},
                                          std::vector<Eigen::Vector2d>* ends = nullptr);

// ---- references per frame ----

enum class ReferenceSource { kLaser, kMap, kCorners };
const char* to_string(ReferenceSource s);

struct ReferenceOptions {
  ReferenceSource source = ReferenceSource::kLaser;
  std::string corners_file;      // kCorners
  double max_scan_gap_s = 0.1;   // kLaser: a frame without a scan this close has no reference
  double max_corner_range = 10;  // kCorners: corners farther from the robot are left out [m]
  CornerOptions corners;
};

// The reference of one image, in the robot frame at the image's time.
struct FrameReference {
  std::size_t frame = 0;
  std::vector<Eigen::Vector2d> points;   // the scan's points (empty for map and corners)
  std::vector<Eigen::Vector2d> corners;  // where vertical edges stand
  std::vector<Eigen::Vector2d> ends;     // kLaser: the scan's ends (scan_corners)
  double scan_gap_s = 0;                 // kLaser: scan time - image time
};

struct References {
  ReferenceSource source = ReferenceSource::kLaser;
  std::string description;  // for people: what was read, how many frames have a reference
  std::vector<FrameReference> frames;  // frames with a reference, increasing
};

// Reads the references of a dataset (the images' odometry times: Dataset::odometry_time).
// Throws InputError: laser0/ or its sensor.yaml missing, scans with no usable range, scans that
// do not overlap the images in time; ground_truth/ files missing for kMap; a bad corners file.
References load_references(const dataset::Dataset& data, const ReferenceOptions& options);

// ---- the number ----

struct OffsetStats {
  int frames = 0;            // frames with a reference and lines
  int corners = 0;           // corners seen in those frames
  int matched = 0;           // of those, with an extracted line within the gate
  double median_abs = 0;     // median |offset| over the matched corners [rad]
  double median_signed = 0;  // median offset (line - corner) [rad]
  bool valid() const { return matched > 0; }
};
// Offsets of the corners (with `ends`: of the ends) to the lines, matched by match_offsets
// among the frame's corners and ends together, with `gate` [rad]; `lines[f]` holds the camera
// bearings of the lines extracted in frame f.
OffsetStats corner_line_offsets(const References& refs,
                                const std::vector<std::vector<double>>& lines,
                                const calib::Extrinsics& mounting,
                                double gate,
                                bool ends = false);
// The signed offset of one corner bearing to its nearest line, NaN when none is within gate.
double nearest_line_offset(double corner, const std::vector<double>& lines, double gate);
// The signed offsets (line - reference, wrapped) of references (bearings) to their nearest
// lines, each NaN when no line is within `gate` or when that line lies nearer another
// reference (mutual nearest neighbours: a line is matched once, so a corner whose edge was
// not extracted does not take the line of its neighbour).
std::vector<double> match_offsets(const std::vector<double>& refs,
                                  const std::vector<double>& lines,
                                  double gate);

// ---- the job ----

struct ReprojectionOptions {
  ReferenceOptions reference;
  double gate_deg = 5.0;            // a corner farther than this from every line is unmatched
  std::vector<std::size_t> frames;  // frames drawn; empty: the middle frame with a reference
  FeaturePipelineOptions features;  // the extraction of the drawn frames
  std::string mask;                 // image mask file instead of the sensor.yaml's
  // Called after each frame whose lines are extracted here (done, total).
  std::function<void(std::size_t, std::size_t)> progress;
  bool IsValid(std::string* why) const;
};

struct ReprojectionResult {
  ReferenceSource source = ReferenceSource::kLaser;
  std::string description;
  double gate = 0;                        // [rad]
  calib::Extrinsics before, after;        // the two mountings (before: the prior)
  OffsetStats stats_before, stats_after;  // the corners
  OffsetStats ends_before, ends_after;    // the scan's ends (kLaser)
  std::vector<std::size_t> frames_drawn;
  cv::Mat picture;  // BGR: one row per drawn frame, before | after
  // Two lines for a terminal: the medians before and after, with the counts.
  std::string message() const;
  // summary.json's "reprojection" object and report.html's section (the picture `png`).
  std::string json() const;
  std::string html(const std::string& png) const;
};

// The check for two mountings: the medians over every frame with a reference (lines[f]: the
// bearings extracted in frame f; an empty `lines` extracts the frames' lines here), and the
// picture of the chosen frames (their lines extracted again, with the centre of each frame).
ReprojectionResult check_reprojection(const dataset::Dataset& data,
                                      const References& refs,
                                      const std::vector<std::vector<double>>& lines,
                                      const calib::Extrinsics& before,
                                      const calib::Extrinsics& after,
                                      const ReprojectionOptions& options);

}  // namespace omnivert::pipeline
