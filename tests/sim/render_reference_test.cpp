// The fast renderer (edge intervals, analytic azimuthal coverage) against the plain
// reference (every pixel casts 32 rays over its footprint against every wall), on frames of
// each preset world: occlusion, partial-height walls and textures must agree.

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
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
    const CameraPose pose =
        camera_pose({w.start.x() + 1.3, w.start.y() + 0.4, 0.6}, Extrinsics{}, 0.9);
    cv::Mat1f fast, ref;
    r.render(pose, fast);
    r.render_reference(pose, 32, ref);
    cv::Mat1f diff = cv::abs(fast - ref);
    const double mean = cv::mean(diff)[0];
    double worst = 0;
    cv::minMaxLoc(diff, nullptr, &worst);
    // Pixels that differ by more than 1/32 of a full contrast step (supersampling quantisation).
    const int big = cv::countNonZero(diff > 8.0);
    std::printf("%s: fast vs reference: mean |diff| %.4f, max %.2f, %d pixels > 8\n",
                name.c_str(),
                mean,
                worst,
                big);
    // Differences come from the reference's 1/32 coverage steps and the texture filters'
    // approximations; a visibility error (wrong wall, wrong order, missed edge) would
    // change whole regions.
    const int pixels = cam.width * cam.height;
    EXPECT_LT(mean, 0.15) << name;
    EXPECT_LT(big, pixels / 1000) << name;
  }
}

float bilinear(const cv::Mat1f& m, double x, double y) {
  const int u = static_cast<int>(std::floor(x)), v = static_cast<int>(std::floor(y));
  const double fx = x - u, fy = y - v;
  return static_cast<float>((1 - fy) * ((1 - fx) * m(v, u) + fx * m(v, u + 1)) +
                            fy * ((1 - fx) * m(v + 1, u) + fx * m(v + 1, u + 1)));
}

// Every ground-truth line is an edge the image shows: along its visible extent, the median
// intensity step across it (3 px apart) is at least 5 grey levels for nearly all lines that
// have no other line within 3 px.
// (Lines hidden by occlusion but listed, or listed at a wrong place, would fail this.)
TEST(GroundTruthLines, EveryListedLineShowsAsAnEdge) {
  const CatadioptricCamera cam;
  for (const std::string name : {"corridor", "office", "hall"}) {
    const World w = world_preset(name);
    const Renderer r(cam, w);
    const auto motion = load_trajectory("paper").pieces(w.start);
    int total = 0, weak = 0;
    for (double t : {0.0, 10.0, 20.0, 25.0}) {
      const CameraPose pose = camera_pose(pose_at(motion, t), Extrinsics{}, 0.9);
      const cv::Mat1f img = r.render(pose);
      const auto lines = r.visible_lines(pose);
      for (const VisibleLine& l : lines) {
        // Only lines the image can resolve: no other line within 3 px (tangentially, at
        // the outer end), where the probes 1.5 px either side would straddle both.
        bool crowded = false;
        for (const VisibleLine& o : lines) {
          if (&o != &l && std::abs(angle_diff(o.bearing, l.bearing)) * l.r_outer < 3.0)
            crowded = true;
        }
        if (crowded) continue;
        std::vector<double> steps;
        const double ca = std::cos(l.bearing), sa = std::sin(l.bearing);
        for (double rr = l.r_inner + 2; rr <= l.r_outer - 2; rr += 1.0) {
          const double x = cam.cx + rr * ca, y = cam.cy + rr * sa;
          steps.push_back(std::abs(bilinear(img, x - 1.5 * sa, y + 1.5 * ca) -
                                   bilinear(img, x + 1.5 * sa, y - 1.5 * ca)));
        }
        if (steps.empty()) continue;
        std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
        ++total;
        if (steps[steps.size() / 2] < 5.0) ++weak;
      }
    }
    std::printf("%s: %d ground-truth lines in 4 frames, %d without a visible step\n",
                name.c_str(),
                total,
                weak);
    EXPECT_GT(total, 100) << name;
    EXPECT_LT(weak, total * 3 / 100) << name;
  }
}

}  // namespace
}  // namespace omnivert::sim
