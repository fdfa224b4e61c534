// Image masks on rendered frames (docs/extraction.md#image-masks): a strut drawn by the
// simulator (sim/robot_overlay) is a line to the extractor until the ground-truth mask hides
// it; the lines far from it keep their bearings to the last bit; the descriptor changes only
// in the areas the mask reaches; the mirror centre is found with part of the rim masked.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/describe/descriptor.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/extract/line_extractor.hpp"
#include "omnivert/extract/mirror_center.hpp"
#include "omnivert/image/image_mask.hpp"
#include "omnivert/sim/renderer.hpp"
#include "omnivert/sim/robot_overlay.hpp"
#include "omnivert/sim/simulator.hpp"

namespace omnivert::sim {
namespace {

struct Frame {
  CatadioptricCamera cam;
  cv::Mat1b image;
  std::vector<VisibleLine> truth;
  MirrorCircle circle;
};

// The corridor seen from the paper trajectory's start, with `overlay` painted before the
// image sensor (seed 7: the same noise with and without the overlay).
Frame render(const RobotOverlay& overlay) {
  Frame f;
  const World w = world_preset("corridor");
  const Renderer r(f.cam, w);
  const auto motion = load_trajectory("paper").pieces(w.start);
  const CameraPose pose = camera_pose(pose_at(motion, 0.0), Extrinsics{}, 0.9);
  cv::Mat1f clean = r.render(pose);
  if (!overlay.empty()) paint_overlay(overlay_picture(overlay, f.cam), clean);
  std::mt19937_64 rng(7);
  apply_image_sensor(clean, ImageSensor{}, rng, f.image);
  f.truth = r.visible_lines(pose);
  f.circle.center = {f.cam.cx, f.cam.cy};
  f.circle.r_min = f.cam.r_min;
  f.circle.r_max = f.cam.r_max;
  return f;
}

// The image angle (degrees) in the middle of the widest gap between ground-truth lines.
double widest_gap_deg(const std::vector<VisibleLine>& truth) {
  std::vector<double> a;
  for (const VisibleLine& l : truth) a.push_back(wrap_positive(l.bearing));
  std::sort(a.begin(), a.end());
  double best = 0, mid = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double next = i + 1 < a.size() ? a[i + 1] : a[0] + kTwoPi;
    if (next - a[i] > best) best = next - a[i], mid = 0.5 * (a[i] + next);
  }
  return rad2deg(wrap_angle(mid));
}

double nearest_deg(const std::vector<VerticalLine>& lines, double deg) {
  double best = 180;
  for (const VerticalLine& l : lines)
    best = std::min(best, std::abs(rad2deg(angle_diff(l.image_angle, deg2rad(deg)))));
  return best;
}

RobotOverlay strut_at(double deg) {
  RobotOverlay o;
  o.strut_angles_deg = {deg};
  o.strut_width_px = 4.0;
  return o;
}

TEST(MaskOnSimulatedFrames, StrutIsALineUntilMasked) {
  const double strut = widest_gap_deg(render({}).truth);
  const RobotOverlay o = strut_at(strut);
  const Frame f = render(o);
  const cv::Mat mask = overlay_mask(overlay_picture(o, f.cam), o.mask_margin_px);

  LineExtractor plain, masked;
  masked.set_mask(mask);
  std::vector<VerticalLine> without, with;
  plain.extract(f.image, f.circle, without);
  masked.extract(f.image, f.circle, with);
  std::printf(
      "strut at %.2f deg: nearest line %.3f deg without the mask, %.3f deg with it; "
      "%zu and %zu lines\n",
      strut,
      nearest_deg(without, strut),
      nearest_deg(with, strut),
      without.size(),
      with.size());
  EXPECT_LT(nearest_deg(without, strut), 1.0);
  EXPECT_GT(nearest_deg(with, strut), 1.0);

  // The lines far from the strut: the same lines at the same bearings, to the last bit.
  int far = 0;
  for (const VerticalLine& l : without) {
    if (std::abs(rad2deg(angle_diff(l.image_angle, deg2rad(strut)))) < 10) continue;
    ++far;
    bool same = false;
    for (const VerticalLine& m : with)
      same = same || (m.polarity == l.polarity && std::abs(m.image_angle - l.image_angle) < 1e-9 &&
                      m.edge_pixels == l.edge_pixels);
    EXPECT_TRUE(same) << "line at " << rad2deg(l.image_angle) << " deg moved or vanished";
  }
  EXPECT_GE(far, 5);
  EXPECT_EQ(static_cast<int>(with.size()), far);
}

TEST(MaskOnSimulatedFrames, AllUsableMaskIsNoMask) {
  const Frame f = render(strut_at(30.0));
  LineExtractor plain, masked;
  masked.set_mask(cv::Mat(f.image.size(), CV_8U, cv::Scalar(255)));
  EXPECT_FALSE(masked.has_mask());
  std::vector<VerticalLine> a, b;
  plain.extract(f.image, f.circle, a);
  masked.extract(f.image, f.circle, b);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].image_angle, b[i].image_angle);
}

// Per histogram pair (area) of a 3-area descriptor: the L2 distance between two rows.
std::vector<double> pair_distances(const DescriptorMatrix& a, const DescriptorMatrix& b, int nb) {
  std::vector<double> d;
  for (int k = 0; k < 3; ++k) {
    double s = 0;
    for (int i = 2 * k * nb; i < 2 * (k + 1) * nb; ++i) s += std::pow(a(0, i) - b(0, i), 2);
    d.push_back(std::sqrt(s));
  }
  return d;
}

TEST(MaskOnSimulatedFrames, DescriptorChangesOnlyWhereMasked) {
  const Frame f = render({});
  LineExtractor ex;
  std::vector<VerticalLine> lines;
  ex.extract(f.image, f.circle, lines);
  ASSERT_FALSE(lines.empty());
  const VerticalLine line =
      *std::max_element(lines.begin(), lines.end(), [](const auto& x, const auto& y) {
        return x.edge_pixels < y.edge_pixels;
      });
  DescriptorExtractor d;
  const double ra = d.area_radius(f.circle);
  // A disc of radius r_a / 2 on the left of the line, in the outer area (3), at the far end
  // from area 2.
  const double a = line.image_angle, r = f.circle.r_min + 5.4 * ra;
  const cv::Point2d c(f.circle.center.x() + r * std::cos(a) - 0.5 * ra * std::sin(a),
                      f.circle.center.y() + r * std::sin(a) + 0.5 * ra * std::cos(a));
  cv::Mat mask(f.image.size(), CV_8U, cv::Scalar(255));
  cv::circle(mask, c, static_cast<int>(0.5 * ra), cv::Scalar(0), cv::FILLED);

  const std::vector<VerticalLine> one = {line};
  DescriptorMatrix plain, masked, all_usable;
  d.compute(f.image, f.circle, one, plain);
  DescriptorExtractor dm;
  dm.set_mask(mask);
  dm.compute(f.image, f.circle, one, masked);
  DescriptorExtractor du;
  du.set_mask(cv::Mat(f.image.size(), CV_8U, cv::Scalar(255)));
  du.compute(f.image, f.circle, one, all_usable);
  EXPECT_EQ((plain - all_usable).cwiseAbs().maxCoeff(), 0.0f);

  const auto dist = pair_distances(plain, masked, d.options().bins);
  std::printf("descriptor change per area (L2, each area unit length): %.2e %.2e %.3f\n",
              dist[0],
              dist[1],
              dist[2]);
  EXPECT_EQ(dist[0], 0.0);
  EXPECT_LT(dist[1], 1e-3);
  EXPECT_GT(dist[2], 0.05);
}

TEST(MaskOnSimulatedFrames, CentreWithPartOfTheRimMasked) {
  // Struts across the rim and a bright blob over a quarter of it, all masked.
  RobotOverlay o;
  o.strut_angles_deg = {-100.0, 20.0, 140.0};
  o.strut_width_px = 8.0;
  o.reflection_angle_deg = 60.0;
  o.reflection_width_deg = 90.0;
  o.reflection_r_inner_px = 150.0;
  o.reflection_r_outer_px = 240.0;
  o.reflection_grey = 200.0;
  const Frame f = render(o);
  const cv::Mat mask = overlay_mask(overlay_picture(o, f.cam), o.mask_margin_px);
  const Eigen::Vector2d truth(f.cam.cx, f.cam.cy);

  CameraGeometry g;
  g.width = f.cam.width;
  g.height = f.cam.height;
  MirrorCenterDetector det;
  det.set_mask(mask);
  std::string why;
  const auto c = det.estimate(f.image, g, &why);
  ASSERT_TRUE(c) << why;
  MirrorCircle prior = *c;
  prior.center += Eigen::Vector2d(4.0, -3.0);
  const auto tracked = det.detect(f.image, prior, &why);
  ASSERT_TRUE(tracked) << why;
  MirrorCenterDetector plain;
  const auto unmasked = plain.estimate(f.image, g, &why);
  std::printf("centre error: %.3f px (estimate), %.3f px (detect), %.3f px without the mask\n",
              (c->center - truth).norm(),
              (tracked->center - truth).norm(),
              unmasked ? (unmasked->center - truth).norm() : -1.0);
  EXPECT_LT((c->center - truth).norm(), 0.3);
  EXPECT_LT((tracked->center - truth).norm(), 0.3);
}

TEST(MaskOnSimulatedFrames, PipelineRefusesAMaskThatHidesTheAnnulus) {
  const Frame f = render({});
  CameraGeometry g;
  g.width = f.cam.width;
  g.height = f.cam.height;
  g.center = Eigen::Vector2d(f.cam.cx, f.cam.cy);
  g.r_min = f.cam.r_min;
  g.r_max = f.cam.r_max;
  FeaturePipeline p(g);
  cv::Mat mask(f.image.size(), CV_8U, cv::Scalar(0));
  mask(cv::Rect(0, 0, 20, 20)) = 255;  // a corner: nothing of the annulus
  p.set_mask(mask);
  FrameFeatures out;
  std::string why;
  EXPECT_FALSE(p.process(f.image, out, &why));
  EXPECT_NE(why.find("leaves only 0% of the annulus"), std::string::npos) << why;
}

}  // namespace
}  // namespace omnivert::sim
