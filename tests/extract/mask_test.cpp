// Image masks (image/image_mask.hpp, `mask:` of sensor.yaml): reading and refusing mask files,
// the eroded usable area, and the line extractor on a drawn pattern with one of its edges
// masked.

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/extract/line_extractor.hpp"
#include "omnivert/image/image_io.hpp"
#include "omnivert/image/image_mask.hpp"
#include "omnivert/sim/radial_pattern.hpp"

namespace omnivert {
namespace {

namespace fs = std::filesystem;

class MaskFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("omnivert_mask_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::string message(const std::string& file, int w, int h) const {
    try {
      read_mask(file, w, h);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(MaskFiles, ReadsGreyMasksAndRefusesTheRest) {
  cv::Mat m(48, 64, CV_8U, cv::Scalar(0));
  m(cv::Rect(10, 10, 5, 4)) = 7;  // any non-zero value is usable
  write_image_atomic(path("m.png"), m);
  const cv::Mat u = read_mask(path("m.png"), 64, 48);
  EXPECT_EQ(u.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(u), 20);
  EXPECT_EQ(u.at<uchar>(10, 10), 255);

  cv::Mat m16(48, 64, CV_16U, cv::Scalar(0));
  m16(cv::Rect(0, 0, 2, 3)) = 1000;
  write_image_atomic(path("m16.png"), m16);
  EXPECT_EQ(cv::countNonZero(read_mask(path("m16.png"), 64, 48)), 6);

  EXPECT_EQ(message(path("m.png"), 640, 480),
            path("m.png") + ": mask is 64x48 but the camera's resolution is 640x480");
  write_image_atomic(path("zero.png"), cv::Mat(48, 64, CV_8U, cv::Scalar(0)));
  EXPECT_EQ(
      message(path("zero.png"), 64, 48),
      path("zero.png") + ": mask has no usable pixel (every pixel is zero; non-zero = usable)");
  write_image_atomic(path("colour.png"), cv::Mat(48, 64, CV_8UC3, cv::Scalar(255, 255, 255)));
  EXPECT_NE(message(path("colour.png"), 64, 48).find("this one has 3 channels"), std::string::npos);
  EXPECT_EQ(message(path("nope.png"), 64, 48), path("nope.png") + ": file not found");
}

TEST_F(MaskFiles, SensorYamlResolvesTheMaskBesideIt) {
  write_image_atomic(path("mask.png"), cv::Mat(48, 64, CV_8U, cv::Scalar(255)));
  {
    std::ofstream y(path("sensor.yaml"));
    y << "resolution: [64, 48]\nmask: mask.png\n";
  }
  const CameraGeometry g = load_camera_geometry(path("sensor.yaml"));
  ASSERT_TRUE(g.mask);
  EXPECT_EQ(fs::path(*g.mask), dir_ / "mask.png");
  {
    std::ofstream y(path("bad.yaml"));
    y << "resolution: [64, 48]\nr_max: 20\nmask: gone.png\n";
  }
  try {
    load_camera_geometry(path("bad.yaml"));
    FAIL() << "a missing mask file was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:3: field 'mask': file 'gone.png' not found"),
              std::string::npos)
        << e.what();
  }
}

TEST(ImageMask, ErosionByTheKernelRadius) {
  cv::Mat u(20, 20, CV_8U, cv::Scalar(255));
  u.at<uchar>(10, 10) = 0;
  const cv::Mat e = erode_mask(u, 1);
  EXPECT_EQ(cv::countNonZero(e), 400 - 9);  // the 3x3 square around the masked pixel
  EXPECT_EQ(e.at<uchar>(0, 0), 255);        // the image border is not eroded
  EXPECT_TRUE(mask_all_usable(cv::Mat(4, 4, CV_8U, cv::Scalar(1))));
  EXPECT_FALSE(mask_all_usable(u));
}

TEST(LineExtractorMask, MaskedEdgesVanishTheOthersStay) {
  sim::RadialPatternOptions o;
  o.seed = 5;
  const auto p = sim::draw_radial_pattern(o);
  LineExtractor plain;
  std::vector<VerticalLine> all;
  plain.extract(p.image, p.circle, all);
  ASSERT_GE(all.size(), 6u);
  // Mask a wedge of +-1.5 degrees around the first line, over the whole annulus.
  const double a = all.front().image_angle;
  cv::Mat mask(p.image.size(), CV_8U, cv::Scalar(255));
  std::vector<cv::Point> wedge = {
      cv::Point(static_cast<int>(p.circle.center.x()), static_cast<int>(p.circle.center.y()))};
  for (double d : {-1.5, 1.5}) {
    const double b = a + deg2rad(d);
    wedge.emplace_back(static_cast<int>(p.circle.center.x() + 400 * std::cos(b)),
                       static_cast<int>(p.circle.center.y() + 400 * std::sin(b)));
  }
  cv::fillConvexPoly(mask, wedge, cv::Scalar(0));
  LineExtractor masked;
  masked.set_mask(mask);
  EXPECT_TRUE(masked.has_mask());
  std::vector<VerticalLine> rest;
  masked.extract(p.image, p.circle, rest);
  for (const VerticalLine& l : rest) EXPECT_GT(std::abs(angle_diff(l.image_angle, a)), deg2rad(1));
  for (const auto& e : masked.last_edge_points())
    EXPECT_EQ(
        mask.at<uchar>(static_cast<int>(std::lround(e.y)), static_cast<int>(std::lround(e.x))),
        255);
  // Every line more than 5 degrees from the wedge: unchanged.
  int far = 0;
  for (const VerticalLine& l : all) {
    if (std::abs(angle_diff(l.image_angle, a)) < deg2rad(5)) continue;
    ++far;
    bool same = false;
    for (const VerticalLine& m : rest) same = same || m.image_angle == l.image_angle;
    EXPECT_TRUE(same) << rad2deg(l.image_angle);
  }
  EXPECT_GE(far, 4);
}

}  // namespace
}  // namespace omnivert
