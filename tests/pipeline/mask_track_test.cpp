// Tracking through a simulated run with mount struts drawn into every frame
// (sim/robot_overlay): without a mask the struts are tracked in every frame at their image
// angles; with the true mask (TrackDatasetOptions::mask) no detection lies within 1 degree
// of a strut (docs/validation.md#image-masks).

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/image/image_io.hpp"
#include "omnivert/pipeline/track_dataset.hpp"
#include "simulated_datasets.hpp"

namespace omnivert::testing {
namespace {

class MaskTrack : public SimulatedDatasets {};

// Detections within 1 degree of a strut (image angle) and the frames that have one.
int near_struts(const std::vector<TrackRow>& rows, const std::vector<double>& struts_deg) {
  int n = 0;
  for (const TrackRow& r : rows)
    for (double s : struts_deg)
      if (std::abs(rad2deg(angle_diff(r.image_angle, deg2rad(s)))) < 1.0) ++n;
  return n;
}

TEST_F(MaskTrack, NoTrackAtTheStrutsWithTheMask) {
  const int frames = 20;
  sim::SimConfig cfg;
  cfg.seed = 1;
  cfg.max_frames = frames;
  cfg.overlay.strut_angles_deg = {45.0, 165.0, -75.0};
  cfg.overlay.strut_width_px = 6.0;
  const fs::path dir = scratch("struts");
  sim::simulate(sim::load_world("corridor"), sim::load_trajectory("paper"), cfg, dir.string());
  const fs::path mask = scratch("struts-mask.png");
  write_image_atomic(
      mask.string(),
      sim::overlay_mask(sim::overlay_picture(cfg.overlay, cfg.camera), cfg.overlay.mask_margin_px));

  dataset::LoadOptions lo;
  lo.require_wheel = false;
  const auto data = dataset::Dataset::load(dir.string(), lo);
  pipeline::TrackDatasetOptions plain;
  const pipeline::TrackDatasetResult without = pipeline::track_dataset(data, plain);
  pipeline::TrackDatasetOptions masked;
  masked.mask = mask.string();
  const pipeline::TrackDatasetResult with = pipeline::track_dataset(data, masked);
  const int n_without = near_struts(without.rows, cfg.overlay.strut_angles_deg);
  const int n_with = near_struts(with.rows, cfg.overlay.strut_angles_deg);
  std::printf(
      "detections within 1 degree of a strut in %d frames: %d without the mask, %d with "
      "it; %zu and %zu detections in all\n",
      frames,
      n_without,
      n_with,
      without.rows.size(),
      with.rows.size());
  EXPECT_GE(n_without, frames);  // each strut's edges, in (nearly) every frame
  EXPECT_EQ(n_with, 0);
  EXPECT_EQ(with.frames_skipped, 0);
}

}  // namespace
}  // namespace omnivert::testing
