#include "omnivert/pipeline/tilt_check.hpp"

#include <algorithm>

#include "omnivert/core/error.hpp"

namespace omnivert::pipeline {

bool TiltCheckOptions::IsValid(std::string* why) const {
  if (frames < 1 || !(correct_deg >= 0.0) || !(lateral_tolerance_px > 0.0)) {
    if (why) *why = "tilt check: need frames >= 1, correct_deg >= 0, lateral_tolerance_px > 0";
    return false;
  }
  return estimator.IsValid(why);
}

TiltEstimate measure_tilt(const dataset::Dataset& data,
                          const FeaturePipelineOptions& pipeline,
                          const TiltCheckOptions& options) {
  TiltEstimator estimator(data.camera(), options.estimator);
  if (!data.camera().has_projection() || data.size() == 0) return estimator.estimate();
  FeaturePipelineOptions po = pipeline;
  po.tilt.setZero();
  po.lines.lateral_tolerance_px =
      std::max(po.lines.lateral_tolerance_px, options.lateral_tolerance_px);
  FeaturePipeline pipe(data.camera(), po);
  const std::size_t n =
      std::min<std::size_t>(static_cast<std::size_t>(options.frames), data.size());
  FrameFeatures f;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = n == 1 ? 0 : k * (data.size() - 1) / (n - 1);
    try {
      if (!pipe.process(data.image(i), f)) continue;
    } catch (const InputError&) {
      continue;  // tracking reports the frames it cannot read
    }
    estimator.add_frame(pipe.line_extractor().last_edge_points(), f.circle, f.lines);
  }
  return estimator.estimate();
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
