#pragma once
// What a real catadioptric image shows besides the scene, drawn in image coordinates (it
// moves with the camera, so it is static in the image): mount struts (dark bars from the
// mirror rim inward) and the robot's own reflection (a sector of a disc near the centre).
// Off by default. The simulator can write the matching ground-truth mask
// (docs/simulator.md#struts-reflection-and-masks).

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/sim/camera_model.hpp"

namespace omnivert::sim {

struct RobotOverlay {
  // Struts: one bar per image angle [deg] (a = atan2(v - cy, u - cx)), strut_width_px wide,
  // from beyond the rim inward to strut_inner_px from the centre (0: the camera's r_min).
  std::vector<double> strut_angles_deg;
  double strut_width_px = 6.0;
  double strut_inner_px = 0.0;
  double strut_grey = 25.0;  // grey level of the bars (before the image sensor's gain)
  // Reflection: the sector of image angles reflection_angle_deg +- reflection_width_deg / 2
  // between radii reflection_r_inner_px and reflection_r_outer_px (0, 0: from the camera's
  // r_min - 3 to r_min + 30% of the annulus). reflection_width_deg 0: none.
  double reflection_angle_deg = 0.0;
  double reflection_width_deg = 0.0;
  double reflection_r_inner_px = 0.0;
  double reflection_r_outer_px = 0.0;
  double reflection_grey = 70.0;
  // Write cam0/mask.png (0 wherever the overlay covers any part of a pixel, grown by
  // mask_margin_px) and `mask: mask.png` in cam0/sensor.yaml.
  bool write_mask = false;
  double mask_margin_px = 1.0;

  bool empty() const { return strut_angles_deg.empty() && !(reflection_width_deg > 0); }
  bool IsValid(std::string* why) const;
};

// The overlay's coverage of each pixel (fraction in [0, 1], 4 x 4 samples per pixel) and
// the grey level there, for a camera.
struct OverlayPicture {
  cv::Mat1f coverage;
  cv::Mat1f grey;
};
OverlayPicture overlay_picture(const RobotOverlay& overlay, const CatadioptricCamera& camera);

// Paints the overlay onto a noise-free rendering: image = (1 - coverage) image + coverage grey.
void paint_overlay(const OverlayPicture& picture, cv::Mat1f& image);

// The ground-truth mask (CV_8UC1, 255 usable, 0 masked): 0 where coverage > 0, grown by
// margin_px (rounded up to whole pixels).
cv::Mat overlay_mask(const OverlayPicture& picture, double margin_px);

}  // namespace omnivert::sim
