#pragma once
// Rendering with a tilted mirror axis (docs/simulator.md#tilt, docs/theory/tilt.md). The
// world is rendered by an upright camera of the same model (mirror axis vertical, the
// renderer's exact method) over a slightly wider annulus; each pixel of the tilted camera
// then takes the upright image's value (bicubic) at the pixel of its own viewing
// direction rotated into the upright frame: d_V = R_VC d_C (core/tilt.hpp).

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/sim/camera_model.hpp"
#include "omnivert/sim/renderer.hpp"
#include "omnivert/sim/world.hpp"

namespace omnivert::sim {

class TiltWarp {
 public:
  // `camera` is the tilted camera; pixels with weight > 0 (the world annulus) are warped.
  TiltWarp(const CatadioptricCamera& camera,
           const World& world,
           const std::vector<int>& px_index,
           const std::vector<float>& px_weight);

  // The tilted image: background (rim, self-reflection) blended with the warped world.
  void render(const CameraPose& pose, const cv::Mat1f& background, cv::Mat1f& image) const;

  const Renderer& upright() const { return *upright_; }

 private:
  std::unique_ptr<Renderer> upright_;
  cv::Mat1f map_x_, map_y_;  // upright-image position of each tilted pixel
  std::vector<int> px_index_;
  std::vector<float> px_weight_;
};

}  // namespace omnivert::sim
