// Mirror rim, centre and annulus on the real sample images (skipped when
// ../shared/data/real is absent): within one camera the centre is one point, so the centres
// found on its images must agree; each is checked against the rim seen on the overlays.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "omnivert/extract/camera_estimate.hpp"
#include "omnivert/extract/mirror_center.hpp"

namespace omnivert {
namespace {

struct RealCamera {
  const char* name;
  std::vector<std::string> files;
  double cx, cy;              // rim centre checked by eye on the overlay, +-3 px
  double rim;                 // rim radius, +-5 px
  double r_min_lo, r_min_hi;  // plausible self-reflection radii + margin
};

std::vector<std::string> numbered(const std::string& pattern, int first, int last) {
  std::vector<std::string> out;
  for (int i = first; i <= last; ++i) {
    char buf[128];
    std::snprintf(buf, sizeof buf, pattern.c_str(), i);
    out.push_back(buf);
  }
  return out;
}

class RealCameras : public ::testing::TestWithParam<RealCamera> {};

TEST_P(RealCameras, RimFoundOnEveryImageAndCentresAgree) {
  const auto& cam = GetParam();
  const std::filesystem::path root = OMNIVERT_REAL_DATA_DIR;
  std::vector<cv::Mat> frames;
  for (const auto& f : cam.files) {
    const auto path = root / f;
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " absent";
    frames.push_back(cv::imread(path.string(), cv::IMREAD_GRAYSCALE));
    ASSERT_FALSE(frames.back().empty()) << path;
  }
  const MirrorCenterDetector det;
  std::vector<Eigen::Vector2d> centres;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    CameraGeometry g;
    g.width = frames[i].cols;
    g.height = frames[i].rows;
    std::string why;
    const auto c = det.estimate(frames[i], g, &why);
    ASSERT_TRUE(c.has_value()) << cam.files[i] << ": " << why;
    std::printf("%-26s centre (%.2f, %.2f) rim %.2f annulus %.1f..%.1f\n",
                cam.files[i].c_str(),
                c->center.x(),
                c->center.y(),
                c->rim_radius,
                c->r_min,
                c->r_max);
    EXPECT_NEAR(c->center.x(), cam.cx, 3.0) << cam.files[i];
    EXPECT_NEAR(c->center.y(), cam.cy, 3.0) << cam.files[i];
    EXPECT_NEAR(c->rim_radius, cam.rim, 5.0) << cam.files[i];
    EXPECT_GE(c->r_min, cam.r_min_lo) << cam.files[i];
    EXPECT_LE(c->r_min, cam.r_min_hi) << cam.files[i];
    centres.push_back(c->center);
  }
  double spread = 0;
  for (const auto& a : centres)
    for (const auto& b : centres) spread = std::max(spread, (a - b).norm());
  std::printf("%s: spread of the centres %.2f px\n", cam.name, spread);
  EXPECT_LE(spread, 1.0);
  if (frames.size() > 1) {
    const CameraEstimate e = estimate_camera(frames);
    EXPECT_EQ(e.used_frames, static_cast<int>(frames.size()));
    EXPECT_NEAR(e.circle.center.x(), cam.cx, 3.0);
    EXPECT_NEAR(e.circle.center.y(), cam.cy, 3.0);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cameras,
    RealCameras,
    ::testing::Values(
        RealCamera{"VMR", numbered("VMRImage%d.jpg", 0, 4), 516.8, 384.1, 452.5, 60, 110},
        RealCamera{"Mei", numbered("imgMei_00%d.jpg", 1, 5), 641.4, 521.4, 353.0, 40, 80},
        RealCamera{"rig", numbered("omnidir_rig/%d.jpg", 1, 9), 630.2, 436.1, 529.0, 50, 90},
        RealCamera{"paracat", {"paracat_1024x768_01.jpg"}, 520.3, 392.6, 389.3, 45, 85}),
    [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace omnivert
