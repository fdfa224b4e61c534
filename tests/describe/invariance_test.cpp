// Rotation and illumination invariance of lines and descriptors (Sec. 3.1, 3.3), on drawn
// images and, when ../shared/data/real is present, on the real sample images.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/eval/invariance.hpp"
#include "omnivert/sim/radial_pattern.hpp"

namespace omnivert {
namespace {

FrameFeatures features_of(const cv::Mat& img,
                          const CameraGeometry& g,
                          const FeaturePipelineOptions& o = {}) {
  FeaturePipeline p(g, o);
  FrameFeatures f;
  std::string why;
  EXPECT_TRUE(p.process(img, f, &why)) << why;
  return f;
}

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[std::min(v.size() - 1, static_cast<std::size_t>(q * v.size()))];
}

CameraGeometry geometry_of(const sim::RadialPatternOptions& o) {
  CameraGeometry g;
  g.width = o.width, g.height = o.height, g.r_min = o.r_min, g.r_max = o.r_max;
  return g;
}

TEST(Invariance, RotatedSceneGivesTheSameLinesShiftedAndTheSameDescriptors) {
  int pairs = 0;
  double worst_shift = 0, worst_dist = 0;
  for (int seed = 1; seed <= 4; ++seed) {
    sim::RadialPatternOptions o;
    o.seed = 40 + seed;
    const auto g = geometry_of(o);
    const FrameFeatures f0 = features_of(sim::draw_radial_pattern(o).image, g);
    for (double deg : {13.0, 47.0, 131.0, 229.0}) {  // not multiples of 90
      auto orot = o;
      orot.rotation_rad = deg2rad(deg);
      orot.noise_seed = 77 + seed;
      const FrameFeatures f1 = features_of(sim::draw_radial_pattern(orot).image, g);
      EXPECT_EQ(f1.lines.size(), f0.lines.size()) << "seed " << seed << " rotation " << deg;
      const auto pr = eval::pair_lines(f0, f1, deg2rad(deg), deg2rad(0.5));
      EXPECT_EQ(pr.size(), f0.lines.size());
      for (const auto& p : pr) {
        ++pairs;
        worst_shift = std::max(worst_shift, std::abs(rad2deg(p.angle_error)));
        worst_dist = std::max(worst_dist, p.descriptor_distance);
      }
    }
  }
  std::printf(
      "rotation: %d line pairs, worst shift error %.4f deg, worst descriptor distance %.3f\n",
      pairs,
      worst_shift,
      worst_dist);
  EXPECT_LE(worst_shift, 0.1);
  EXPECT_LE(worst_dist, 0.25);
}

// rotated_usable: a copy's pixel is usable when its bilinear sample reads only usable pixels
// of the original (inside its frame and its mask), and not when it reads beyond either.
TEST(Invariance, RotatedUsableMarksWhatTheCopyReallySaw) {
  const cv::Size size(120, 90);
  const Eigen::Vector2d c(61.3, 44.8);
  cv::Mat usable(size, CV_8U, cv::Scalar(255));
  usable.colRange(0, 30).setTo(0);  // the left quarter masked
  for (const double deg : {7.0, 41.0, 137.0}) {
    const double t = deg2rad(deg);
    const cv::Mat frame = eval::rotated_usable(cv::Mat(), size, c, t);
    const cv::Mat masked = eval::rotated_usable(usable, size, c, t);
    ASSERT_EQ(frame.size(), size);
    ASSERT_EQ(frame.type(), CV_8UC1);
    int checked = 0;
    for (int v = 0; v < size.height; ++v)
      for (int u = 0; u < size.width; ++u) {
        // The copy's pixel at image angle a + t comes from the original's at angle a.
        const Eigen::Vector2d d = Eigen::Vector2d(u, v) - c;
        const Eigen::Vector2d q = c + Eigen::Rotation2Dd(-t).toRotationMatrix() * d;
        const bool inside =
            q.x() >= 1 && q.y() >= 1 && q.x() <= size.width - 2 && q.y() <= size.height - 2;
        const bool outside = q.x() < -1 || q.y() < -1 || q.x() > size.width || q.y() > size.height;
        if (inside) {
          EXPECT_EQ(frame.at<uchar>(v, u), 255) << u << "," << v << " at " << deg;
        }
        if (outside) {
          EXPECT_EQ(frame.at<uchar>(v, u), 0) << u << "," << v << " at " << deg;
        }
        if (inside && q.x() >= 31) {
          EXPECT_EQ(masked.at<uchar>(v, u), 255) << u << "," << v;
        }
        if (q.x() < 29) {
          EXPECT_EQ(masked.at<uchar>(v, u), 0) << u << "," << v;
        }
        checked += inside || outside;
      }
    EXPECT_GT(checked, size.area() * 9 / 10);
    EXPECT_GT(cv::countNonZero(frame == 0), size.area() / 20);  // the corners
  }
}

TEST(Invariance, GainAndGammaChangeDescriptorsLittle) {
  // Grey levels kept where a gain of 1.5 does not saturate (saturation destroys edges: it is
  // not an illumination change; the study program reports it separately).
  double worst = 0;
  int pairs = 0;
  for (int seed = 1; seed <= 4; ++seed) {
    sim::RadialPatternOptions o;
    o.seed = 60 + seed;
    o.max_contrast = 80;
    const auto p = sim::draw_radial_pattern(o);
    cv::Mat img = p.image * (165.0 / 255.0);  // brightest level x1.5 stays below 255
    const auto g = geometry_of(o);
    const FrameFeatures f0 = features_of(img, g);
    for (double gain : {0.6, 0.8, 1.25, 1.5}) {
      for (double gamma : {0.7, 1.0, 1.4}) {
        const FrameFeatures f1 = features_of(eval::relight(img, gain, gamma), g);
        for (const auto& pr : eval::pair_lines(f0, f1, 0.0, deg2rad(0.3))) {
          ++pairs;
          worst = std::max(worst, pr.descriptor_distance);
        }
      }
    }
  }
  std::printf("gain x0.6..x1.5, gamma 0.7..1.4: %d line pairs, worst descriptor distance %.3f\n",
              pairs,
              worst);
  EXPECT_GT(pairs, 100);
  EXPECT_LE(worst, 0.3);
}

// --- Real images (skipped when ../shared/data/real is absent) ---

struct RealCase {
  const char* file;
  double cx, cy;  // centre checked by eye on the overlay, +-2 px
};

class RealImages : public ::testing::TestWithParam<RealCase> {};

TEST_P(RealImages, CentreLinesAndInvariances) {
  const auto path = std::filesystem::path(OMNIVERT_REAL_DATA_DIR) / GetParam().file;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " absent";
  const cv::Mat gray = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(gray.empty());
  FeaturePipelineOptions po;
  po.lines.threshold = LineThreshold::kTopK;  // real mirrors: walls fill part of the annulus
  po.lines.top_k = 20;
  FrameFeatures probe = features_of(gray, {}, po);
  EXPECT_NEAR(probe.circle.center.x(), GetParam().cx, 2.0);
  EXPECT_NEAR(probe.circle.center.y(), GetParam().cy, 2.0);
  const cv::Mat& img = gray;
  // The copies are rotated about a known centre: give it, with the annulus, as a sensor.yaml
  // would (centre detection has tests of its own). The annulus ends where a rotation can
  // bring no new content into a descriptor (VMRImage0's mirror is cropped by the frame).
  CameraGeometry geo;
  geo.center = probe.circle.center;
  geo.r_min = probe.circle.r_min;
  geo.r_max = std::min(
      probe.circle.r_max,
      eval::rotation_safe_r_max(probe.circle.center, gray.cols, gray.rows, probe.circle.r_min));
  const FrameFeatures f0 = features_of(img, geo, po);
  ASSERT_GE(f0.lines.size(), 2u);

  std::vector<double> rot_dist, rot_shift, light_dist;
  int found = 0, expected = 0;
  for (double deg : {17.0, 71.0, 199.0}) {
    const FrameFeatures f1 =
        features_of(eval::rotate_about(img, f0.circle.center, deg2rad(deg)), geo, po);
    const auto pr = eval::pair_lines(f0, f1, deg2rad(deg), deg2rad(0.3));
    expected += static_cast<int>(f0.lines.size());
    found += static_cast<int>(pr.size());
    for (const auto& p : pr) {
      rot_dist.push_back(p.descriptor_distance);
      rot_shift.push_back(std::abs(rad2deg(p.angle_error)));
    }
  }
  for (double gain : {0.6, 0.8}) {
    for (double gamma : {0.7, 1.4}) {
      const FrameFeatures f1 = features_of(eval::relight(img, gain, gamma), geo, po);
      for (const auto& p : eval::pair_lines(f0, f1, 0.0, deg2rad(0.3)))
        light_dist.push_back(p.descriptor_distance);
    }
  }
  std::printf(
      "%s: centre (%.2f, %.2f), %zu lines; rotation: %d/%d lines again, shift median %.3f p90 %.3f "
      "deg, "
      "descriptor distance median %.3f p90 %.3f max %.3f; light: median %.3f p90 %.3f max %.3f\n",
      GetParam().file,
      f0.circle.center.x(),
      f0.circle.center.y(),
      f0.lines.size(),
      found,
      expected,
      percentile(rot_shift, 0.5),
      percentile(rot_shift, 0.9),
      percentile(rot_dist, 0.5),
      percentile(rot_dist, 0.9),
      percentile(rot_dist, 1.0),
      percentile(light_dist, 0.5),
      percentile(light_dist, 0.9),
      percentile(light_dist, 1.0));
  // The top 20 of a real image are cut from many lines of similar length, so which of them a
  // rotated copy keeps moves with the last hundredth of a pixel of the centre (VMRImage0:
  // 49/60 at one centre, 47/60 at one 0.02 px away): three quarters, not four fifths.
  EXPECT_GE(found, 0.75 * expected);
  // Real lines are weaker and less straight than drawn ones (KaidanOmni1 is hand-held, its
  // axis tilted, and keeps 3 lines, so its 90th percentile is the largest of 9 shifts): the
  // median shift error must meet the drawn images' 0.1 degree, the tail 0.2.
  EXPECT_LE(percentile(rot_shift, 0.5), 0.1);
  EXPECT_LE(percentile(rot_shift, 0.9), 0.2);
  EXPECT_LE(percentile(rot_dist, 0.9), 0.25);
  EXPECT_LE(percentile(light_dist, 0.9), 0.3);
}

INSTANTIATE_TEST_SUITE_P(Shared,
                         RealImages,
                         ::testing::Values(RealCase{"VMRImage0.jpg", 516.7, 384.1},
                                           RealCase{"imgMei_001.jpg", 641.4, 521.3},
                                           RealCase{"KaidanOmni1.jpg", 325.1, 246.6}),
                         [](const auto& info) {
                           std::string n = info.param.file;
                           return n.substr(0, n.find('.'));
                         });

}  // namespace
}  // namespace omnivert
