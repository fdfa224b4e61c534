// The check by eye (paper Sec. 9.2, Figs. 23 and 26): the geometry against known answers, the
// picture shifted by a known yaw, and bad laser data refused with its file, line and problem.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/dataset/laser.hpp"
#include "omnivert/pipeline/reprojection.hpp"
#include "omnivert/viz/reprojection_plot.hpp"

namespace omnivert::pipeline {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A scan of segments (the scanner at the origin, 0.25 degree over a full turn), exact ranges.
dataset::LaserScan scan_of(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& walls,
                           double range_max = 8.0) {
  dataset::LaserScan s;
  s.angle_min = -kPi;
  s.angle_increment = deg2rad(0.25);
  s.range_min = 0.05;
  s.range_max = range_max;
  for (int k = 0; k < 1440; ++k) {
    const double a = s.angle_min + k * s.angle_increment;
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    double best = kInf;
    for (const auto& [p, q] : walls) {
      const Eigen::Vector2d u = q - p;
      const double den = d.x() * u.y() - d.y() * u.x();
      if (std::abs(den) < 1e-12) continue;
      const double t = (p.x() * u.y() - p.y() * u.x()) / den;
      const double w = (p.x() * d.y() - p.y() * d.x()) / den;
      if (t > 0 && w >= 0 && w <= 1) best = std::min(best, t);
    }
    s.ranges.push_back(static_cast<float>(best > range_max ? kInf : best));
  }
  return s;
}

int near(const std::vector<Eigen::Vector2d>& found, const Eigen::Vector2d& p, double tol) {
  int n = 0;
  for (const auto& f : found) n += (f - p).norm() < tol ? 1 : 0;
  return n;
}

TEST(Reprojection, CameraBearingOfKnownGeometry) {
  // Camera at rho (cos phi, sin phi) = (0, 0.2), yaw phi + psi = 90 deg: a point 1 m ahead of
  // the robot is at (1, -0.2) in the camera frame's axes turned by -90 deg.
  const calib::Extrinsics x{kPi / 2, 0.2, 0.0};
  const Eigen::Vector2d p(1.0, 0.2);
  EXPECT_NEAR(camera_bearing(x, p), -kPi / 2, 1e-12);
  EXPECT_NEAR(camera_bearing(x, Eigen::Vector2d(0.0, 1.2)), 0.0, 1e-12);
  // The paper's mounting against its hand measurement.
  const calib::Extrinsics truth{-0.34, 0.23, 0.33}, prior{0.0, 0.2, 0.0};
  const Eigen::Vector2d q(2.0, 1.0);
  const Eigen::Vector2d c = truth.position();
  const double expected = std::atan2(q.y() - c.y(), q.x() - c.x()) - truth.yaw();
  EXPECT_NEAR(camera_bearing(truth, q), wrap_angle(expected), 1e-12);
  EXPECT_NEAR(camera_bearing(prior, q), std::atan2(1.0, 1.8), 1e-12);
}

TEST(Reprojection, YawOffsetShiftsEveryBearingByIt) {
  const calib::Extrinsics x{-0.34, 0.23, 0.33};
  calib::Extrinsics off = x;
  off.psi += deg2rad(3.0);
  for (const Eigen::Vector2d& p :
       {Eigen::Vector2d(2, 1), Eigen::Vector2d(-1, 3), Eigen::Vector2d(0.5, -4)})
    EXPECT_NEAR(angle_diff(camera_bearing(off, p), camera_bearing(x, p)), -deg2rad(3.0), 1e-12);
}

// The drawn corner: the angle of the red tick outside the annulus, from its pixels.
double drawn_tick_angle(const cv::Mat& picture, const MirrorCircle& c) {
  double sx = 0, sy = 0;
  for (int v = 0; v < picture.rows; ++v)
    for (int u = 0; u < picture.cols; ++u) {
      const cv::Vec3b px = picture.at<cv::Vec3b>(v, u);
      const double r = std::hypot(u - c.center.x(), v - c.center.y());
      if (r > c.r_max + 4 && px[2] > 200 && px[1] < 60 && px[0] < 60) {
        sx += px[2] * (u - c.center.x());
        sy += px[2] * (v - c.center.y());
      }
    }
  return std::atan2(sy, sx);
}

TEST(Reprojection, MountingOffByAKnownYawShiftsTheDrawnCornerByIt) {
  const cv::Mat black(480, 640, CV_8UC1, cv::Scalar(0));
  MirrorCircle c;
  c.center = {320.5, 240.25};
  c.r_min = 60;
  c.r_max = 200;
  const calib::Extrinsics x{-0.34, 0.23, 0.33};
  calib::Extrinsics off = x;
  off.psi += deg2rad(7.0);
  const Eigen::Vector2d corner(2.0, 1.5);
  for (const int sign : {1, -1}) {
    auto angle_of = [&](const calib::Extrinsics& m) {
      viz::ReprojectionLayer l;
      l.corners.emplace_back(camera_bearing(m, corner), 2.0);
      return drawn_tick_angle(viz::draw_reprojection(black, c, sign, {}, l), c);
    };
    const double shift = angle_diff(angle_of(off), angle_of(x));
    EXPECT_NEAR(shift, -sign * deg2rad(7.0), deg2rad(0.1)) << "bearing_sign " << sign;
    EXPECT_NEAR(angle_of(x), sign * camera_bearing(x, corner), deg2rad(0.1));
  }
}

TEST(Reprojection, CornersOfARoomAndTheEndOfAWall) {
  // A room 6 x 4 m around the scanner, and a wall 0.5 m long in front of its far side (its
  // shadow on the far side, x = 1.25 to 2.5 m, hides no corner).
  const Eigen::Vector2d a(-2, -1.5), b(4, -1.5), c(4, 2.5), d(-2, 2.5);
  const Eigen::Vector2d w0(0.5, 1.0), w1(1.0, 1.0);
  const auto corners = scan_corners(scan_of({{a, b}, {b, c}, {c, d}, {d, a}, {w0, w1}}));
  for (const auto& p : {a, b, c, d}) EXPECT_EQ(near(corners, p, 0.01), 1) << p.transpose();
  // The free wall's two ends stand in front of the room's wall (jumps to farther points):
  // found within half a ray's spacing at their range (0.25 deg x 1.4 m = 6 mm).
  EXPECT_EQ(near(corners, w0, 0.01), 1);
  EXPECT_EQ(near(corners, w1, 0.01), 1);
  // The wall hides part of the room's side: the points where it meets the shadow are not
  // corners (the nearer surface ends there, not the farther one).
  EXPECT_EQ(corners.size(), 6u);
}

TEST(Reprojection, NoReturnBeyondAWallEndIsAnEdgeButNotWhereTheRangeRunsOut) {
  // A wall from (3, 1) to (3, -0.5), nothing behind its upper end within range, the long
  // wall y = -1 behind its lower end; the long wall runs out of range (8 m) on both sides:
  // the two ends of the short wall are the only corners.
  const auto found = scan_corners(scan_of({{{3, 1}, {3, -0.5}}, {{-20, -1}, {20, -1}}}));
  EXPECT_EQ(near(found, {3, 1}, 0.015), 1);
  EXPECT_EQ(near(found, {3, -0.5}, 0.015), 1);
  EXPECT_EQ(found.size(), 2u);
}

TEST(Reprojection, OffsetsAreGatedAndMedianed) {
  References refs;
  FrameReference f;
  f.corners = {{2, 0}, {0, 2}, {-2, 0}};
  refs.frames.push_back(f);
  // Lines 1 and 2 degrees off the first two corners; none near the third.
  const calib::Extrinsics m{0, 0, 0};
  const std::vector<std::vector<double>> lines = {{deg2rad(1.0), kPi / 2 - deg2rad(2.0)}};
  const OffsetStats s = corner_line_offsets(refs, lines, m, deg2rad(5));
  EXPECT_EQ(s.corners, 3);
  EXPECT_EQ(s.matched, 2);
  EXPECT_NEAR(rad2deg(s.median_abs), 1.5, 1e-9);
  EXPECT_NEAR(rad2deg(s.median_signed), -0.5, 1e-9);
  EXPECT_TRUE(std::isnan(nearest_line_offset(kPi, lines[0], deg2rad(5))));
  EXPECT_NEAR(nearest_line_offset(kPi - 0.01, {-kPi + 0.01}, 0.1), 0.02, 1e-12);  // across +-pi
}

TEST(Reprojection, ALineIsMatchedToItsNearestCornerOnly) {
  // Two corners 0.5 degree apart and one line 0.4 degree from the first: the line is the
  // second's (0.1 degree), and the first, whose own edge was not extracted, stays unmatched.
  const auto off = match_offsets({0.0, deg2rad(0.5)}, {deg2rad(0.4)}, deg2rad(5));
  ASSERT_EQ(off.size(), 2u);
  EXPECT_TRUE(std::isnan(off[0]));
  EXPECT_NEAR(rad2deg(off[1]), -0.1, 1e-9);
}

TEST(Reprojection, PosesComposeAndInvert) {
  const Pose2d a(1, 2, 0.3), b(-0.5, 0.2, -1.1);
  const Pose2d ab = compose(a, b);
  const Pose2d back = compose(inverse(a), ab);
  EXPECT_TRUE(back.isApprox(b, 1e-12));
  EXPECT_TRUE(compose(a, inverse(a)).isZero(1e-12));
}

}  // namespace
}  // namespace omnivert::pipeline
