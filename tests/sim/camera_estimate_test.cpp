// estimate_camera (what `omnivert camera` runs) on rendered frames of a moving robot, whose
// mirror centre, rim and self-reflection are known exactly: the joint centre and radii, and
// the mask proposed for a strut and a robot reflection painted onto every frame.

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/extract/camera_estimate.hpp"
#include "omnivert/sim/renderer.hpp"
#include "omnivert/sim/sensors.hpp"
#include "omnivert/sim/simulator.hpp"
#include "omnivert/sim/trajectory.hpp"

namespace omnivert::sim {
namespace {

// `n` noisy frames spread over the first 26 s of the paper trajectory in the office.
std::vector<cv::Mat> moving_frames(const CatadioptricCamera& cam, int n) {
  const World w = world_preset("office");
  const Renderer r(cam, w);
  const auto motion = load_trajectory("paper").pieces(w.start);
  std::mt19937_64 rng(11);
  std::vector<cv::Mat> frames;
  for (int i = 0; i < n; ++i) {
    const CameraPose pose = camera_pose(pose_at(motion, 26.0 * i / (n - 1)), Extrinsics{}, 0.9);
    cv::Mat1b img;
    apply_image_sensor(r.render(pose), ImageSensor{}, rng, img);
    frames.push_back(img);
  }
  return frames;
}

TEST(CameraEstimate, FindsTheRenderedCentreRimAndSelfReflection) {
  const CatadioptricCamera cam;
  const auto frames = moving_frames(cam, 8);
  const CameraEstimate e = estimate_camera(frames);
  const Eigen::Vector2d truth(cam.cx, cam.cy);
  std::printf(
      "centre (%.3f, %.3f) vs (%.3f, %.3f): %.3f px; rim %.3f vs %.3f; r_min %.2f; "
      "spread %.3f px over %zu frames\n",
      e.circle.center.x(),
      e.circle.center.y(),
      truth.x(),
      truth.y(),
      (e.circle.center - truth).norm(),
      e.circle.rim_radius,
      cam.rim_radius(),
      e.circle.r_min,
      e.spread_px,
      e.frames.size());
  EXPECT_LE((e.circle.center - truth).norm(), 0.3);
  EXPECT_NEAR(e.circle.rim_radius, cam.rim_radius(), 1.0);
  EXPECT_NEAR(e.circle.r_max, cam.rim_radius() * 0.97, 1.0);
  // r_min = self-reflection radius + 10%.
  EXPECT_NEAR(e.circle.r_min / 1.1, cam.self_radius(), 1.0);
  EXPECT_EQ(e.used_frames, 8);
  EXPECT_LE(e.spread_px, 1.0);
  // One sensor.yaml line per field.
  const std::string y = camera_sensor_yaml(e, "mask.png", "test");
  EXPECT_NE(y.find("resolution: [640, 480]"), std::string::npos);
  EXPECT_NE(y.find("bearing_sign: 1"), std::string::npos);
  EXPECT_NE(y.find("mask: mask.png"), std::string::npos);
}

TEST(CameraEstimate, MaskCoversAStaticStrutAndRobotReflection) {
  const CatadioptricCamera cam;
  auto frames = moving_frames(cam, 24);
  // What never moves in the image: a strut across the annulus and the rim (a 10-pixel band at
  // 40 degrees), and a part of the robot seen in the mirror (a sector next to r_min).
  cv::Mat painted = cv::Mat::zeros(frames[0].size(), CV_8U);
  const cv::Point2d c(cam.cx, cam.cy);
  const double a = deg2rad(40.0);
  const cv::Point2d dir(std::cos(a), std::sin(a));
  cv::line(painted, c + cam.r_min * dir, c + (cam.rim_radius() + 8) * dir, 255, 10);
  cv::ellipse(painted, c, {110, 110}, 0, 200, 250, 255, cv::FILLED);
  cv::circle(painted, c, static_cast<int>(cam.r_min), 0, cv::FILLED);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 2.0);
  for (auto& f : frames) {
    for (int v = 0; v < f.rows; ++v)
      for (int u = 0; u < f.cols; ++u)
        if (painted.at<uchar>(v, u))
          f.at<uchar>(v, u) = cv::saturate_cast<uchar>(70 + (u % 7) * 3 + noise(rng));
  }
  const CameraEstimate e = estimate_camera(frames);
  ASSERT_FALSE(e.mask.empty()) << e.mask_note;
  EXPECT_LE((e.circle.center - Eigen::Vector2d(cam.cx, cam.cy)).norm(), 0.3);
  cv::Mat annulus = cv::Mat::zeros(painted.size(), CV_8U);
  cv::circle(annulus, c, static_cast<int>(e.circle.r_max), 255, cv::FILLED);
  cv::circle(annulus, c, static_cast<int>(e.circle.r_min), 0, cv::FILLED);
  const cv::Mat target = painted & annulus, rest = annulus & ~painted;
  const double covered =
      cv::countNonZero(target & (e.mask == 0)) / static_cast<double>(cv::countNonZero(target));
  const double wrong =
      cv::countNonZero(rest & (e.mask == 0)) / static_cast<double>(cv::countNonZero(rest));
  std::printf("static pixels masked: %.1f%%; rest of the annulus masked: %.2f%%\n",
              100 * covered,
              100 * wrong);
  EXPECT_GE(covered, 0.95);
  EXPECT_LT(wrong, 0.05);
}

TEST(CameraEstimate, NoMaskFromStillFramesOrOneFrame) {
  const CatadioptricCamera cam;
  const auto moving = moving_frames(cam, 2);
  const std::vector<cv::Mat> still(6, moving[0]);
  const CameraEstimate e = estimate_camera(still);
  EXPECT_TRUE(e.mask.empty());
  EXPECT_NE(e.mask_note.find("hardly change"), std::string::npos) << e.mask_note;
  const CameraEstimate one = estimate_camera({moving[1]});
  EXPECT_TRUE(one.mask.empty());
  EXPECT_NE(one.mask_note.find("1 frame(s)"), std::string::npos) << one.mask_note;
}

}  // namespace
}  // namespace omnivert::sim
