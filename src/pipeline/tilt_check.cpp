#include "omnivert/pipeline/tilt_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/core/tilt.hpp"

namespace omnivert::pipeline {

bool TiltCheckOptions::IsValid(std::string* why) const {
  if (frames < 1 || passes < 1 || !(given_deg >= 0.0 && given_deg < 30.0) ||
      !std::isfinite(given_direction_deg) || !(correct_deg >= 0.0) ||
      !(lateral_tolerance_px > 0.0)) {
    if (why)
      *why =
          "tilt check: need frames >= 1, passes >= 1, correct_deg >= 0, "
          "lateral_tolerance_px > 0 and a given tilt in [0, 30) deg";
    return false;
  }
  return estimator.IsValid(why);
}

namespace {

// The images a measurement looks at: `count` of them, image(k) the k-th (may throw InputError).
struct ImageSet {
  CameraGeometry camera;
  std::size_t count = 0;
  std::function<cv::Mat(std::size_t)> image;
};

// One pass: the tilt left on the images after the pipeline's own rectification (po.tilt;
// zero: the images as they are).
TiltEstimate measure_once(const ImageSet& set,
                          const FeaturePipelineOptions& po,
                          const TiltCheckOptions& options) {
  TiltEstimator estimator(set.camera, options.estimator);
  FeaturePipeline pipe(set.camera, po);
  FrameFeatures f;
  for (std::size_t k = 0; k < set.count; ++k) {
    try {
      if (!pipe.process(set.image(k), f)) continue;
    } catch (const InputError&) {
      continue;  // tracking reports the frames it cannot read
    }
    estimator.add_frame(pipe.line_extractor().last_edge_points(), f.circle, f.lines);
  }
  return estimator.estimate();
}

// The tilt vector of R(second) R(first): the first rectification, then what was left.
Eigen::Vector2d compose(const Eigen::Vector2d& first, const Eigen::Vector2d& second) {
  const Eigen::Vector3d axis =
      tilt_rotation_of_vector(second) * tilt_rotation_of_vector(first) * Eigen::Vector3d::UnitZ();
  const double h = std::hypot(axis.x(), axis.y());
  if (h == 0.0) return Eigen::Vector2d::Zero();
  return std::atan2(h, axis.z()) / h * Eigen::Vector2d(axis.x(), axis.y());
}

}  // namespace

Eigen::Vector2d TiltCheckOptions::given_vector() const {
  if (!(given_deg > 0.0)) return Eigen::Vector2d::Zero();
  const double d = deg2rad(given_direction_deg);
  return deg2rad(given_deg) * Eigen::Vector2d(std::cos(d), std::sin(d));
}

TiltChoice choose_tilt(const TiltCheckOptions& options,
                       const std::function<TiltEstimate()>& measure) {
  TiltChoice c;
  if (options.given_deg > 0.0) {
    c.tilt.vector = options.given_vector();  // known: rectified with it, not measured
    c.rectified = true;
    return c;
  }
  if (!options.enabled) return c;
  c.tilt = measure();
  c.rectified = c.tilt.valid && c.tilt.tilt_deg() > options.correct_deg;
  c.warning = tilt_warning(c.tilt, options, c.rectified);
  return c;
}

namespace {

TiltEstimate measure_tilt(const ImageSet& set,
                          const FeaturePipelineOptions& pipeline,
                          const TiltCheckOptions& options) {
  if (!set.camera.has_projection() || set.count == 0)
    return TiltEstimator(set.camera, options.estimator).estimate();
  // Pass 1: a wider line support keeps a curved vertical whole (docs/theory/tilt.md).
  FeaturePipelineOptions po = pipeline;
  po.tilt.setZero();
  po.lines.lateral_tolerance_px =
      std::max(po.lines.lateral_tolerance_px, options.lateral_tolerance_px);
  TiltEstimate tilt = measure_once(set, po, options);
  // Pass 2, when the frames will be rectified: what is left on them, with the usual support.
  if (options.passes < 2 || !tilt.valid || tilt.tilt_deg() <= options.correct_deg) return tilt;
  po = pipeline;
  po.tilt = tilt.vector;
  TiltEstimate rest = measure_once(set, po, options);
  if (!rest.valid) return tilt;
  rest.vector = compose(tilt.vector, rest.vector);
  return rest;
}

}  // namespace

TiltEstimate measure_tilt(const dataset::Dataset& data,
                          const FeaturePipelineOptions& pipeline,
                          const TiltCheckOptions& options) {
  ImageSet set;
  set.camera = data.camera();
  set.count = std::min<std::size_t>(static_cast<std::size_t>(options.frames), data.size());
  const std::size_t n = set.count;
  set.image = [&data, n](std::size_t k) {
    return data.image(n == 1 ? 0 : k * (data.size() - 1) / (n - 1));
  };
  return measure_tilt(set, pipeline, options);
}

TiltEstimate measure_image_tilt(const cv::Mat& image,
                                const CameraGeometry& camera,
                                const FeaturePipelineOptions& pipeline,
                                const TiltCheckOptions& options) {
  ImageSet set;
  set.camera = camera;
  set.count = 1;
  set.image = [&image](std::size_t) { return image; };
  return measure_tilt(set, pipeline, options);
}

std::string tilt_line(const TiltEstimate& tilt, bool rectified) {
  if (tilt.valid) return tilt.describe() + (rectified ? "; frames rectified" : "");
  if (!rectified) return {};
  char buf[128];
  std::snprintf(buf,
                sizeof buf,
                "frames rectified with the given tilt, %.2f deg towards bearing %.1f deg",
                tilt.tilt_deg(),
                tilt.direction_deg());
  return buf;
}

std::string tilt_warning(const TiltEstimate& tilt,
                         const TiltCheckOptions& options,
                         bool corrected) {
  if (!tilt.valid || tilt.tilt_deg() <= options.estimator.warn_deg) return {};
  return "the mirror axis is tilted from the vertical: " + tilt.describe() +
         (corrected ? "; the frames were rectified to an upright camera"
                    : "; the bearings of radial lines are off by up to tan(el) times the tilt") +
         " (docs/extraction.md, \"Tilt\")";
}

}  // namespace omnivert::pipeline
