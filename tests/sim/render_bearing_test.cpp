// Rendered geometry against an independent computation: a vertical
// edge at a known world position must appear at its predicted bearing within 0.05 degree.
//
// The prediction uses docs/theory/conventions.md directly (camera centre at rho (cos phi, sin phi)
// in the robot frame, beta = atan2(y_f - y_C, x_f - x_C) - (theta_R + phi + psi)). The measurement
// does not use the renderer's code: it fits the edge's image angle to the rendered
// intensities. For any anti-aliasing that integrates a footprint symmetric about the pixel
// centre, the normalised intensity f of a pixel crossed by a straight edge is 0.5 plus a
// multiple of the pixel centre's signed distance d to the edge; with the radial line at image
// angle alpha through the mirror centre, d = -x sin(alpha) + y cos(alpha). So
// f - 0.5 = A x + B y over the transition pixels, a linear least-squares fit, and
// alpha = atan2(-A, B).

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "omnivert/core/angles.hpp"
#include "omnivert/sim/renderer.hpp"
#include "omnivert/sim/sensors.hpp"
#include "omnivert/sim/simulator.hpp"

namespace omnivert::sim {
namespace {

// A dark wall (x = 2, y from -6 to 6) that turns bright at y = edge_y; flat floor and
// ceiling, no texture noise.
World edge_world(double edge_y) {
  World w;
  w.name = "edge";
  w.height = 2.6;
  w.floor = {90, 0, 0.5};
  w.ceiling = {120, 0, 0.5};
  Wall wall;
  wall.from = {2.0, -6.0};
  wall.to = {2.0, 6.0};
  wall.intensity = 50;
  wall.texture = 0;
  Strip s;
  s.s0 = edge_y + 6.0;
  s.s1 = 12.0;
  s.intensity = 210;
  wall.strips.push_back(s);
  w.walls.push_back(wall);
  return w;
}

// Predicted camera bearing of the world vertical line at (xf, yf) (docs/theory/conventions.md).
double predicted_bearing(
    double xr, double yr, double th, double phi, double rho, double psi, double xf, double yf) {
  const double xc = xr + rho * std::cos(th + phi);
  const double yc = yr + rho * std::sin(th + phi);
  return wrap_angle(std::atan2(yf - yc, xf - xc) - (th + phi + psi));
}

// Image angle of the edge, fitted to the intensities of pixels in the ring r0..r1 within
// +-window of the approximate angle a_guess (the window only selects the region).
double fit_edge_angle(const cv::Mat1f& img,
                      double cx,
                      double cy,
                      double a_guess,
                      double r0,
                      double r1,
                      double window,
                      int* used = nullptr) {
  // Intensity levels on either side, from the region itself.
  double lo = 1e9, hi = -1e9;
  std::vector<Eigen::Vector3d> px;  // x, y, intensity
  for (int v = 0; v < img.rows; ++v) {
    for (int u = 0; u < img.cols; ++u) {
      const double x = u - cx, y = v - cy, r = std::hypot(x, y);
      if (r < r0 || r > r1) continue;
      if (std::abs(angle_diff(std::atan2(y, x), a_guess)) > window) continue;
      px.emplace_back(x, y, img(v, u));
      lo = std::min(lo, static_cast<double>(img(v, u)));
      hi = std::max(hi, static_cast<double>(img(v, u)));
    }
  }
  Eigen::Matrix2d N = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  int n = 0;
  for (const auto& p : px) {
    const double f = (p.z() - lo) / (hi - lo);
    if (f < 0.03 || f > 0.97) continue;
    const Eigen::Vector2d a(p.x(), p.y());
    N += a * a.transpose();
    b += a * (f - 0.5);
    ++n;
  }
  if (used) *used = n;
  const Eigen::Vector2d AB = N.ldlt().solve(b);
  double alpha = std::atan2(-AB.x(), AB.y());
  if (std::abs(angle_diff(alpha, a_guess)) > kPi / 2) alpha = wrap_angle(alpha + kPi);
  return alpha;
}

TEST(RenderBearing, VerticalEdgeAtPredictedBearingWithinFiveHundredthsOfADegree) {
  const Extrinsics x;  // paper's values
  double max_err_deg = 0.0;
  int cases = 0;
  for (int sign : {1, -1}) {
    CatadioptricCamera cam;
    cam.bearing_sign = sign;
    for (double edge_y : {0.3, -1.7, 2.9}) {
      const World world = edge_world(edge_y);
      Renderer renderer(cam, world);
      for (double th : {0.0, 0.7, 2.2, 3.1, -1.3, -2.6}) {
        // Robot so that the wall is in view and the edge well inside the annulus.
        const double xr = -0.4, yr = 0.1 * th;
        const CameraPose pose = camera_pose({xr, yr, th}, x, 0.9);
        const cv::Mat1f img = renderer.render(pose);
        const double beta = predicted_bearing(xr, yr, th, x.phi, x.rho, x.psi, 2.0, edge_y);
        // Radii where the wall (not floor or ceiling) is seen at the edge.
        const double d = std::hypot(2.0 - pose.x, edge_y - pose.y);
        const double r0 = std::max(cam.radius_of_elevation(std::atan2(0.15 - 0.9, d)), cam.r_min);
        const double r1 =
            std::min(cam.radius_of_elevation(std::atan2(2.4 - 0.9, d)), cam.r_max - 2);
        ASSERT_GT(r1 - r0, 40.0);
        int used = 0;
        const double a =
            fit_edge_angle(img, cam.cx, cam.cy, sign * beta, r0, r1, deg2rad(3.0), &used);
        ASSERT_GT(used, 30);
        const double measured_beta = wrap_angle(sign * a);
        const double err = rad2deg(std::abs(angle_diff(measured_beta, beta)));
        EXPECT_LT(err, 0.05) << "sign " << sign << " edge_y " << edge_y << " theta " << th;
        max_err_deg = std::max(max_err_deg, err);
        ++cases;
        // The ground-truth line list gives the same bearing.
        bool found = false;
        for (const VisibleLine& l : renderer.visible_lines(pose)) {
          if (std::abs(l.distance - d) < 1e-9) {
            EXPECT_NEAR(angle_diff(l.bearing, beta), 0.0, 1e-9);
            found = true;
          }
        }
        EXPECT_TRUE(found);
      }
    }
  }
  std::printf("bearing error over %d rendered edges: max %.6f deg\n", cases, max_err_deg);
}

// The same with the default image sensor (noise 2 grey levels, gain flicker) and a 0.7 px
// blur: the edge stays within 0.05 degree of its prediction.
TEST(RenderBearing, NoisyBlurredEdgeStillWithinFiveHundredthsOfADegree) {
  const Extrinsics x;
  CatadioptricCamera cam;
  const World world = edge_world(0.3);
  Renderer renderer(cam, world);
  ImageSensor sensor;
  sensor.blur_sigma = 0.7;
  std::mt19937_64 rng(5);
  double max_err_deg = 0.0;
  for (double th : {0.0, 0.7, 2.2, -1.3}) {
    const double xr = -0.4, yr = 0.1 * th;
    const CameraPose pose = camera_pose({xr, yr, th}, x, 0.9);
    cv::Mat1b noisy;
    apply_image_sensor(renderer.render(pose), sensor, rng, noisy);
    cv::Mat1f img;
    noisy.convertTo(img, CV_32F);
    const double beta = predicted_bearing(xr, yr, th, x.phi, x.rho, x.psi, 2.0, 0.3);
    const double d = std::hypot(2.0 - pose.x, 0.3 - pose.y);
    const double r0 = std::max(cam.radius_of_elevation(std::atan2(0.15 - 0.9, d)), cam.r_min);
    const double r1 = std::min(cam.radius_of_elevation(std::atan2(2.4 - 0.9, d)), cam.r_max - 2);
    const double a = fit_edge_angle(img, cam.cx, cam.cy, beta, r0, r1, deg2rad(3.0));
    const double err = rad2deg(std::abs(angle_diff(a, beta)));
    EXPECT_LT(err, 0.05) << "theta " << th;
    max_err_deg = std::max(max_err_deg, err);
  }
  std::printf("bearing error with noise and blur: max %.4f deg\n", max_err_deg);
}

// A dark panel of partial height: its sides are vertical edges visible only from the panel's
// bottom to its top; the ground truth's radial extent must match where the image shows it.
TEST(RenderBearing, PartialHeightEdgeExtentMatchesTheImage) {
  World w = edge_world(5.5);
  Panel door;
  door.s0 = 5.0;
  door.s1 = 6.0;  // y from -1 to 0
  door.z0 = 0.0;
  door.z1 = 1.4;
  door.intensity = 210;
  w.walls[0].panels.push_back(door);
  CatadioptricCamera cam;
  Renderer renderer(cam, w);
  const CameraPose pose{0.0, 0.0, 0.0, 0.9};
  const cv::Mat1f img = renderer.render(pose);
  const auto lines = renderer.visible_lines(pose);
  // Edge at y = 0 (panel side s = 6).
  const double d = 2.0;
  const VisibleLine* side = nullptr;
  for (const auto& l : lines) {
    if (std::abs(l.distance - d) < 1e-9) side = &l;
  }
  ASSERT_NE(side, nullptr);
  EXPECT_NEAR(side->r_outer, cam.radius_of_elevation(std::atan2(1.4 - 0.9, d)), 1e-6);
  // Across the line just inside r_outer the image changes (door vs wall); just outside it
  // does not (wall on both sides).
  auto step_across = [&](double r) {
    const double a = side->bearing, da = 2.0 / r;
    const auto at = [&](double ang) {
      return img(static_cast<int>(std::lround(cam.cy + r * std::sin(ang))),
                 static_cast<int>(std::lround(cam.cx + r * std::cos(ang))));
    };
    return std::abs(at(a + da) - at(a - da));
  };
  EXPECT_GT(step_across(side->r_outer - 4), 100.0);
  EXPECT_LT(step_across(side->r_outer + 4), 1.0);
}

// An edge hidden by a nearer wall is not in the ground truth; when the camera moves so that
// it shows, it is.
TEST(RenderBearing, OcclusionRemovesHiddenEdges) {
  World w = edge_world(0.0);
  Wall blocker;
  blocker.from = {1.0, -0.5};
  blocker.to = {1.0, 0.5};
  blocker.intensity = 128;
  blocker.texture = 0;
  w.walls.push_back(blocker);
  CatadioptricCamera cam;
  Renderer renderer(cam, w);
  auto has_edge = [&](const CameraPose& p) {
    for (const auto& l : renderer.visible_lines(p)) {
      if (renderer.edges()[static_cast<std::size_t>(l.line_id)].p.isApprox(
              Eigen::Vector2d(2.0, 0.0)))
        return true;
    }
    return false;
  };
  EXPECT_FALSE(has_edge({0.0, 0.0, 0.0, 0.9}));
  EXPECT_TRUE(has_edge({0.0, 2.5, 0.0, 0.9}));
}

}  // namespace
}  // namespace omnivert::sim
