// A tilted mirror axis (docs/theory/tilt.md): rendered frames of a known tilt in, the tilt
// estimated from their lines out; the bearings of the rectified frames against the ground
// truth; the geometry of core/tilt.hpp against the camera model. The table printed by
// TiltTable is the extraction part of docs/validation.md, "Tilt".

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/tilt.hpp"
#include "omnivert/extract/line_extractor.hpp"
#include "omnivert/extract/tilt_estimator.hpp"
#include "omnivert/sim/renderer.hpp"
#include "omnivert/sim/simulator.hpp"

namespace omnivert::sim {
namespace {

MirrorCircle circle_of(const CatadioptricCamera& cam) {
  MirrorCircle c;
  c.center = {cam.cx, cam.cy};
  c.r_min = cam.r_min;
  c.r_max = cam.r_max;
  return c;
}

CatadioptricCamera tilted(double tilt_deg, double direction_deg) {
  CatadioptricCamera cam;
  cam.tilt_deg = tilt_deg;
  cam.tilt_direction_deg = direction_deg;
  return cam;
}

// Frames of the office tour at the given times, rendered with the camera's tilt.
std::vector<std::pair<cv::Mat1b, CameraPose>> frames(const Renderer& r,
                                                     const std::vector<double>& times) {
  const auto motion = load_trajectory("paper").pieces(r.world().start);
  std::mt19937_64 rng(11);
  std::vector<std::pair<cv::Mat1b, CameraPose>> out;
  for (double t : times) {
    const CameraPose pose = camera_pose(pose_at(motion, t), Extrinsics{}, 0.9);
    cv::Mat1b img;
    apply_image_sensor(r.render(pose), ImageSensor{}, rng, img);
    out.emplace_back(img, pose);
  }
  return out;
}

// The tilt measured on `images` as tilt_check does it: a wider line support, all frames.
TiltEstimate measure(const CatadioptricCamera& cam,
                     const std::vector<std::pair<cv::Mat1b, CameraPose>>& images) {
  LineExtractorOptions lo;
  lo.lateral_tolerance_px = 3.5;
  LineExtractor extractor(lo);
  TiltEstimator estimator(cam.geometry());
  const MirrorCircle circle = circle_of(cam);
  for (const auto& [img, pose] : images) {
    std::vector<VerticalLine> lines;
    extractor.extract(img, circle, lines);
    estimator.add_frame(extractor.last_edge_points(), circle, lines);
  }
  return estimator.estimate();
}

struct BearingErrors {
  int found = 0, truth = 0;  // long ground-truth lines found within 0.5 degree / all of them
  double rms_deg = 0.0;
  // RMS [deg] of the lines along the tilt (|sin(b - d)| < 0.5) and across it (the rest).
  double rms_along_deg = 0.0, rms_across_deg = 0.0;
};

// Extraction (optionally on the rectified frame) against the ground truth's upright bearings.
BearingErrors bearing_errors(const Renderer& r,
                             const std::vector<std::pair<cv::Mat1b, CameraPose>>& images,
                             const Eigen::Vector2d* rectify,
                             double direction = 0.0) {
  const CatadioptricCamera& cam = r.camera();
  const MirrorCircle circle = circle_of(cam);
  // The lines the calibration uses (pipeline::DatasetRunOptions::min_annulus_fraction): at
  // least half the annulus, so that the nearest line to a long true line is a long one.
  LineExtractorOptions lo;
  lo.threshold = LineThreshold::kFractionOfAnnulus;
  LineExtractor extractor(lo);
  std::optional<TiltRectifier> rect;
  if (rectify) rect.emplace(cam.geometry(), *rectify);
  BearingErrors e;
  double sum2 = 0.0, along2 = 0.0, across2 = 0.0;
  int along = 0, across = 0;
  for (const auto& [img, pose] : images) {
    cv::Mat upright = img;
    if (rect) rect->apply(img, circle, upright);
    std::vector<VerticalLine> lines;
    extractor.extract(upright, circle, lines);
    for (const VisibleLine& g : r.visible_lines(pose)) {
      if (g.r_outer - g.r_inner < 0.5 * (cam.r_max - cam.r_min)) continue;
      ++e.truth;
      double best = kPi;
      for (const VerticalLine& l : lines) {
        const double d = angle_diff(cam.bearing_sign * l.image_angle, g.bearing);
        if (std::abs(d) < std::abs(best)) best = d;
      }
      if (rad2deg(std::abs(best)) < 0.5) {
        ++e.found;
        sum2 += best * best;
        if (std::abs(std::sin(g.bearing - direction)) < 0.5) {
          ++along;
          along2 += best * best;
        } else {
          ++across;
          across2 += best * best;
        }
      }
    }
  }
  e.rms_deg = e.found ? rad2deg(std::sqrt(sum2 / e.found)) : 0.0;
  e.rms_along_deg = along ? rad2deg(std::sqrt(along2 / along)) : 0.0;
  e.rms_across_deg = across ? rad2deg(std::sqrt(across2 / across)) : 0.0;
  return e;
}

TEST(Tilt, RotationLeansTheAxisTowardsTheDirection) {
  const double t = deg2rad(2.0), d = deg2rad(40.0);
  const Eigen::Vector3d axis = tilt_rotation(t, d) * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(axis.x(), std::sin(t) * std::cos(d), 1e-15);
  EXPECT_NEAR(axis.y(), std::sin(t) * std::sin(d), 1e-15);
  EXPECT_NEAR(axis.z(), std::cos(t), 1e-15);
  EXPECT_TRUE(tilt_rotation_of_vector(t * Eigen::Vector2d(std::cos(d), std::sin(d)))
                  .isApprox(tilt_rotation(t, d), 1e-14));
}

TEST(Tilt, NadirImageIsAtGammaSinTOverXiPlusCosT) {
  // The down direction of the upright frame, seen by the tilted camera: bearing d,
  // elevation -(pi/2 - t), radius gamma sin t / (xi + cos t) (docs/theory/tilt.md).
  const CatadioptricCamera cam;
  const double t = deg2rad(3.0), d = deg2rad(-70.0);
  const Eigen::Vector3d down_c = tilt_rotation(t, d).transpose() * -Eigen::Vector3d::UnitZ();
  Eigen::Vector2d px;
  ASSERT_TRUE(cam.project(down_c, px));
  const double rv = cam.gamma * std::sin(t) / (cam.xi + std::cos(t));
  EXPECT_NEAR((px - Eigen::Vector2d(cam.cx, cam.cy)).norm(), rv, 1e-9);
  EXPECT_NEAR(std::atan2(px.y() - cam.cy, px.x() - cam.cx), d, 1e-9);
}

TEST(Tilt, FirstOrderOffsetOfAVerticalMatchesTheExactProjection) {
  // A world vertical at upright bearing b: its pixel at elevation el lies r tan(el) t
  // sin(b - d) off the radial line of angle b, to first order in t (docs/theory/tilt.md).
  const CatadioptricCamera cam;
  const double t = deg2rad(0.5), d = deg2rad(10.0), b = deg2rad(100.0);
  const Eigen::Matrix3d Rcv = tilt_rotation(t, d).transpose();
  for (double el_deg : {-40.0, -20.0, 0.0, 15.0}) {
    const double el = deg2rad(el_deg);
    Eigen::Vector2d px;
    ASSERT_TRUE(cam.project(Rcv * unit_direction(b, el), px));
    const Eigen::Vector2d rel = px - Eigen::Vector2d(cam.cx, cam.cy);
    const double lateral = -rel.x() * std::sin(b) + rel.y() * std::cos(b);
    const double r = cam.radius_of_elevation(el);
    const double first_order = r * std::tan(el) * t * std::sin(b - d);
    EXPECT_NEAR(lateral, first_order, 0.02 * std::abs(first_order) + 2e-3) << el_deg;
  }
}

// Five frames (the datasets' check uses 20): within 0.15 degree, the direction within 3.
TEST(Tilt, EstimatedFromRenderedFramesWithinOnePointFiveTenthsOfADegree) {
  const World w = world_preset("office");
  const std::vector<double> times = {0.0, 6.0, 12.0, 18.0, 24.0};
  for (const auto& [tilt, dir] : {std::pair{2.0, 40.0}, {1.0, -120.0}, {3.0, 170.0}}) {
    const Renderer r(tilted(tilt, dir), w);
    const TiltEstimate e = measure(r.camera(), frames(r, times));
    std::printf(
        "true %.1f deg towards %.0f: %s, rms %.3f px\n", tilt, dir, e.describe().c_str(), e.rms_px);
    ASSERT_TRUE(e.valid);
    EXPECT_NEAR(e.tilt_deg(), tilt, 0.15);
    EXPECT_NEAR(rad2deg(angle_diff(e.direction(), deg2rad(dir))), 0.0, 3.0);
  }
}

TEST(Tilt, EstimateOfAnUprightCameraIsNearZero) {
  const World w = world_preset("office");
  const Renderer r(CatadioptricCamera{}, w);
  const TiltEstimate e = measure(r.camera(), frames(r, {0.0, 6.0, 12.0, 18.0, 24.0}));
  std::printf("upright: %s\n", e.describe().c_str());
  ASSERT_TRUE(e.valid);
  // Measured 0.04 degree; far below the 0.25 degree at which the pipeline corrects.
  EXPECT_LT(e.tilt_deg(), 0.08);
}

TEST(Tilt, RectifiedFramesGiveTheUprightBearings) {
  const World w = world_preset("office");
  const Renderer r(tilted(2.0, 40.0), w);
  const auto images = frames(r, {0.0, 6.0, 12.0, 18.0, 24.0});
  const Eigen::Vector2d x =
      deg2rad(2.0) * Eigen::Vector2d(std::cos(deg2rad(40.0)), std::sin(deg2rad(40.0)));
  const BearingErrors raw = bearing_errors(r, images, nullptr);
  const BearingErrors fixed = bearing_errors(r, images, &x);
  std::printf("2 deg: raw %d of %d lines, rms %.4f deg; rectified %d of %d, rms %.4f deg\n",
              raw.found,
              raw.truth,
              raw.rms_deg,
              fixed.found,
              fixed.truth,
              fixed.rms_deg);
  EXPECT_LT(fixed.rms_deg, raw.rms_deg / 3.0);
  EXPECT_GT(fixed.found, raw.found);
}

// The extraction rows of docs/validation.md, "Tilt": for each tilt, the long ground-truth
// lines found within 0.5 degree and their bearing RMS, as extracted and after rectifying
// with the tilt estimated from the same frames.
TEST(Tilt, TableOfExtractionAgainstTilt) {
  const World w = world_preset("office");
  const std::vector<double> times = {0.0, 4.0, 8.0, 12.0, 16.0, 20.0, 24.0, 28.0};
  const double dir = 40.0;
  std::printf("tilt  estimate       | raw: found  rms   along across | rectified: found  rms\n");
  int found0 = 0;
  for (double tilt : {0.0, 0.5, 1.0, 2.0, 3.0}) {
    const Renderer r(tilted(tilt, dir), w);
    const auto images = frames(r, times);
    const TiltEstimate e = measure(r.camera(), images);
    ASSERT_TRUE(e.valid);
    const BearingErrors raw = bearing_errors(r, images, nullptr, deg2rad(dir));
    const BearingErrors fixed = bearing_errors(r, images, &e.vector, deg2rad(dir));
    std::printf("%.1f  %.3f@%6.1f | %3d/%3d %.4f %.4f %.4f | %3d/%3d %.4f\n",
                tilt,
                e.tilt_deg(),
                e.direction_deg(),
                raw.found,
                raw.truth,
                raw.rms_deg,
                raw.rms_along_deg,
                raw.rms_across_deg,
                fixed.found,
                fixed.truth,
                fixed.rms_deg);
    if (tilt == 0.0) found0 = raw.found;
    EXPECT_NEAR(e.tilt_deg(), tilt, 0.1);
    EXPECT_LT(fixed.rms_deg, 0.05) << tilt;
    // Rectified, a tilted camera keeps most lines; the part of the upright view beyond the
    // tilted rim is missing, which shortens some lines below the 50% criterion.
    EXPECT_GE(fixed.found, found0 * 7 / 10) << tilt;
    if (tilt >= 1.0) {
      EXPECT_LT(fixed.rms_deg, raw.rms_deg / 2.5) << tilt;
    }
  }
}

}  // namespace
}  // namespace omnivert::sim
