#pragma once
// Calibration as the robot drives, the filter's own use (paper Sec. 8.2): each image, with
// the wheel travel since the one before, goes through the frame pipeline (Sec. 2-3), the
// tracker (Sec. 4, 9.1) and the filter (Sec. 8.2) when it arrives, and an estimate with its
// covariance comes out after it. Nothing looks ahead:
//   - the bearings used are chosen frame by frame (lines of at least
//     input.min_annulus_fraction of the annulus; a track whose line was short for
//     input.split_after_short frames continues as a new track), without the batch input's
//     fallback to shorter lines, which needs the whole run (DatasetRunOptions::enough_tracks);
//   - a track enters the filter at its first bearing, whatever its final length;
//   - the crossing guard ahead of a track's start (calib::guard_before_starts) is not made.
// Until the robot has turned filter.bootstrap_rotation, the start-up window collects frames
// and the estimate is the prior's (StreamingEstimate::bootstrapping); the window is solved in
// the frame that completes the turn, which takes longer than the others.
// Memory stays bounded by the tracker's look-back, the filter's state (tracks not seen for
// association.max_missed_frames frames are marginalised) and one FrameEstimate per frame.
//
//   StreamingCalibrator cal(camera, wheel_base, options);
//   for each image: StreamingEstimate e = cal.add_frame(t_ns, image, travel_since_previous);
//   cal.finish();  // solves a window still open (a run that never turned)
//
// `omnivert calibrate --streaming` runs it over a dataset (CalibrateDatasetOptions::streaming).

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "omnivert/calib/calibrate.hpp"
#include "omnivert/calib/calibration_filter.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/match/tracker.hpp"
#include "omnivert/match/tracks_io.hpp"
#include "omnivert/pipeline/calibration_input.hpp"

namespace omnivert::pipeline {

struct StreamingOptions {
  FeaturePipelineOptions features;
  TrackerOptions tracker = recommended_dataset_tracker_options();
  // Prior, models and filter; its robot.wheel_base is replaced by the calibrator's.
  calib::CalibrationOptions calibration = calib::recommended_options();
  // Which bearings the filter is given: min_annulus_fraction, crowded_sigma_scale,
  // split_after_short (the others need the whole run and are not used).
  DatasetRunOptions input;
  // False with the reason in *why (may be null), naming the group first.
  bool IsValid(std::string* why) const;
};

// The new pieces of tracks (input.split_after_short) get ids from this one up, in the order
// they start (the tracker's own ids stay below it).
inline constexpr int kFirstPieceId = 1 << 30;

// What a frame gave.
struct StreamingEstimate {
  std::int64_t frame = 0;  // index of the frame, from 0
  std::int64_t timestamp_ns = 0;
  bool described = false;     // false: no image, or the mirror was not found (no lines then)
  std::string problem;        // why not described, or what the frame pipeline warned of
  bool bootstrapping = true;  // the start-up window still collects frames (prior's estimate)
  calib::Extrinsics extrinsics;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int lines = 0;     // lines extracted
  int bearings = 0;  // bearings given to the filter
  int features = 0;  // tracks in the filter's state after the frame
  // Time spent on the frame [ms], measured on this thread: extraction and descriptors,
  // tracker, filter.
  double front_end_ms = 0.0, tracker_ms = 0.0, filter_ms = 0.0;
  double latency_ms() const { return front_end_ms + tracker_ms + filter_ms; }
};

class StreamingCalibrator {
 public:
  // `wheel_base` [m] (> 0) is the tracker's odometry gate's and the filter's. Throws
  // InputError on invalid options, or a mask the camera names that cannot be read.
  StreamingCalibrator(const CameraGeometry& camera,
                      double wheel_base,
                      const StreamingOptions& options);
  ~StreamingCalibrator();
  StreamingCalibrator(const StreamingCalibrator&) = delete;
  StreamingCalibrator& operator=(const StreamingCalibrator&) = delete;

  // One image as it arrives. `wheel_travel`: the cumulative wheel travel (left, right) [m]
  // from the previous image's time to this image's, every wheel sample between included
  // (wheel_travel_between_images); for the first image, its travel alone. Throws InputError
  // on non-finite travel.
  StreamingEstimate add_frame(std::int64_t timestamp_ns,
                              const cv::Mat& image,
                              const std::vector<Eigen::Vector2d>& wheel_travel);

  // End of the run: a start-up window still open is solved. The estimate after it is
  // filter().extrinsics() and filter().covariance().
  void finish();

  const calib::CalibrationFilter& filter() const;
  const TrackerStats& tracker_stats() const;
  // The last frame's lines with their tracks (tracks.csv rows) and the filter's input made
  // of them (wheel travel of eq. 14-15, bearings).
  const std::vector<TrackRow>& last_rows() const;
  const calib::FrameInput& last_input() const;
  // Bearings of lines shorter than input.min_annulus_fraction left out so far.
  int short_bearings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace omnivert::pipeline
