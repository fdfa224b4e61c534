#pragma once
// The tilt of the mirror axis measured on a dataset before tracking (docs/theory/tilt.md):
// a few frames spread over the dataset go through the frame pipeline with a wider line
// support (a tilted vertical is a curve, not a radial line), and the TiltEstimator fits the
// tilt to the edge pixels of all their lines.

#include <functional>
#include <string>

#include "omnivert/dataset/dataset.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/extract/tilt_estimator.hpp"

namespace omnivert::pipeline {

struct TiltCheckOptions {
  bool enabled = true;  // measure when the camera's xi and gamma are known
  int frames = 20;      // frames spread evenly over the dataset
  // Above this the frames are rectified to the upright camera before tracking
  // (FeaturePipelineOptions::tilt); above estimator.warn_deg a warning says so.
  double correct_deg = 0.25;
  // The line support of the measuring pass [px]: wide enough for a curved vertical
  // (up to 3.4 px off its best radial line at 3 degrees, docs/theory/tilt.md).
  double lateral_tolerance_px = 3.5;
  // Passes of the measurement: the second measures what is left on the frames rectified with
  // the first, with the ordinary line support, and adds it (the curved verticals of the first
  // pass give a slightly short estimate, docs/theory/tilt.md#estimate). 1: the first alone.
  int passes = 2;
  // The tilt when it is known (e.g. measured once with `omnivert extract` on still frames):
  // above zero the frames are rectified with given_deg towards given_direction_deg and
  // nothing is measured.
  double given_deg = 0.0;
  double given_direction_deg = 0.0;
  TiltEstimatorOptions estimator;

  // The given tilt as a vector t (cos d, sin d) [rad] (zero when none is given).
  Eigen::Vector2d given_vector() const;

  bool IsValid(std::string* why) const;
};

// The tilt over `options.frames` frames of `data`, extracted with `pipeline` (its own tilt
// is ignored). Not valid when the camera has no xi and gamma or too few lines were found.
TiltEstimate measure_tilt(const dataset::Dataset& data,
                          const FeaturePipelineOptions& pipeline,
                          const TiltCheckOptions& options);

// The tilt a run's frames are rectified with (docs/theory/tilt.md): the given one
// (options.given_deg), or else, when options.enabled, the one `measure` returns if it exceeds
// options.correct_deg. What track_dataset and the streaming run decide.
struct TiltChoice {
  TiltEstimate tilt;       // the measurement (valid), or the given vector (not valid)
  bool rectified = false;  // the frames are to be rectified with tilt.vector
  std::string warning;     // tilt_warning's, for a measured tilt
};
TiltChoice choose_tilt(const TiltCheckOptions& options,
                       const std::function<TiltEstimate()>& measure);

// The tilt of one image (`omnivert extract`), measured as measure_tilt measures a dataset.
TiltEstimate measure_image_tilt(const cv::Mat& image,
                                const CameraGeometry& camera,
                                const FeaturePipelineOptions& pipeline,
                                const TiltCheckOptions& options);

// One line for the terminal: the measured tilt and whether the frames were rectified, or the
// given tilt they were rectified with; empty when the tilt was neither measured nor given.
std::string tilt_line(const TiltEstimate& tilt, bool rectified);

// The warning for an estimate above options.estimator.warn_deg, else an empty string.
std::string tilt_warning(const TiltEstimate& tilt, const TiltCheckOptions& options, bool corrected);

}  // namespace omnivert::pipeline
