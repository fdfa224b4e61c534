// The fast renderer (edge intervals, analytic azimuthal coverage) against the plain
// reference (every pixel casts 32 rays over its footprint against every wall), on frames of
// each preset world: occlusion, partial-height walls and textures must agree.

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "omnivert/sim/renderer.hpp"
#include "omnivert/sim/simulator.hpp"

namespace omnivert::sim {
namespace {

TEST(RenderReference, FastRendererMatchesPlainRayCasting) {
  CatadioptricCamera cam;
  cam.width = 320;
  cam.height = 240;
  cam.cx = 160.4;
  cam.cy = 119.7;
  cam.gamma = 65;
  cam.r_min = 30;
  cam.r_max = 107;
  for (const std::string name : {"corridor", "office", "hall"}) {
    const World w = world_preset(name);
    Renderer r(cam, w);
    const CameraPose pose = camera_pose({w.start.x() + 1.3, w.start.y() + 0.4, 0.6}, Extrinsics{}, 0.9);
    cv::Mat1f fast, ref;
    r.render(pose, fast);
    r.render_reference(pose, 32, ref);
    cv::Mat1f diff = cv::abs(fast - ref);
    const double mean = cv::mean(diff)[0];
    double worst = 0;
    cv::minMaxLoc(diff, nullptr, &worst);
    // Pixels that differ by more than 1/32 of a full contrast step (supersampling quantisation).
    const int big = cv::countNonZero(diff > 8.0);
    std::printf("%s: fast vs reference: mean |diff| %.4f, max %.2f, %d pixels > 8\n", name.c_str(), mean, worst, big);
    // Differences come from the reference's 1/32 coverage steps and the texture filters'
    // approximations; a visibility error (wrong wall, wrong order, missed edge) would
    // change whole regions.
    const int pixels = cam.width * cam.height;
    EXPECT_LT(mean, 0.15) << name;
    EXPECT_LT(big, pixels / 1000) << name;
  }
}

}  // namespace
}  // namespace omnivert::sim
