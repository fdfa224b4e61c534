#pragma once
// Tracking a whole dataset: every image through the frame pipeline (Sec. 2-3), every frame
// through the tracker (Sec. 4, 9.1) with the wheel travel between frames. Used by
// `omnivert track` and by the calibration.
//
// A frame whose image cannot be read, or whose mirror is not found, is reported in
// `warnings` and passed to the tracker with no lines, so that frame numbers and odometry
// stay aligned; tracking goes on. A dataset with no images, or with no frame that could be
// processed, is an InputError.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "omnivert/dataset/dataset.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/match/tracker.hpp"
#include "omnivert/match/tracks_io.hpp"
#include "omnivert/pipeline/tilt_check.hpp"

namespace omnivert::pipeline {

struct TrackDatasetOptions {
  FeaturePipelineOptions pipeline;
  TrackerOptions tracker = recommended_dataset_tracker_options();
  // Use the wheel odometry for the tracker's bearing gate when the dataset has it (and the
  // gate is enabled in `tracker`; its wheel base is taken from wheel0/sensor.yaml).
  bool use_odometry = true;
  // Image mask file (image_mask.hpp) used instead of the `mask:` of cam0/sensor.yaml; empty:
  // that one, if any.
  std::string mask;
  // The tilt of the mirror axis: measured first (when pipeline.tilt is zero and the camera's
  // xi and gamma are known), warned about and corrected above its thresholds.
  TiltCheckOptions tilt;
  // Threads reading images and extracting lines and descriptors (0: every core). The
  // mirror centre is located frame after frame and the tracker sees the frames in order, so
  // the result is the same, byte for byte, for every thread count.
  int threads = 0;
};

struct TrackDatasetResult {
  std::vector<TrackRow> rows;
  TrackerStats stats;
  std::int64_t frames = 0;
  std::int64_t frames_skipped = 0;  // unreadable, or no mirror found
  std::vector<std::string> warnings;
  std::vector<FrameFeatures> features;  // per frame, when keep_features is set
  TiltEstimate tilt;                    // the measured tilt (not valid: not measured)
  bool tilt_corrected = false;          // frames rectified with tilt.vector
};

// `progress(done, total)` is called after each frame when set.
TrackDatasetResult track_dataset(const dataset::Dataset& data,
                                 const TrackDatasetOptions& options,
                                 const std::function<void(std::size_t, std::size_t)>& progress = {},
                                 bool keep_features = false);

// The rows of an earlier tracks.csv (`omnivert track` or `calibrate`), checked against the
// dataset: every row's frame must be one of its images, with that image's timestamp. A
// tracks.csv of another dataset, or of a re-recorded one, is an InputError naming the file
// and line.
TrackDatasetResult read_tracks_for_dataset(const std::string& file, const dataset::Dataset& data);

}  // namespace omnivert::pipeline
