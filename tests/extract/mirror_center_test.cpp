// Mirror centre (Sec. 2 step 1) on drawn images with known centres.

#include <cstdio>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "omnivert/extract/mirror_center.hpp"
#include "omnivert/sim/radial_pattern.hpp"

namespace omnivert {
namespace {

TEST(MirrorCenter, EstimateFindsCentreAndRimWithoutPrior) {
  for (int seed = 1; seed <= 10; ++seed) {
    sim::RadialPatternOptions o;
    o.seed = 100 + seed;
    const auto p = sim::draw_radial_pattern(o);
    MirrorCenterDetector det;
    CameraGeometry g;
    g.width = o.width;
    g.height = o.height;
    std::string why;
    const auto c = det.estimate(p.image, g, &why);
    ASSERT_TRUE(c.has_value()) << why;
    EXPECT_LE((c->center - p.circle.center).norm(), 0.3) << "seed " << seed;
    EXPECT_NEAR(c->rim_radius, o.rim_radius, 0.5);
    EXPECT_NEAR(c->r_max, o.rim_radius * 0.97, 1.0);
    EXPECT_NEAR(c->r_min, o.r_min, 3.0);
  }
}

TEST(MirrorCenter, DetectFollowsAShiftedCentre) {
  sim::RadialPatternOptions o;
  o.seed = 7;
  const auto p = sim::draw_radial_pattern(o);
  MirrorCircle prior = p.circle;
  prior.center += Eigen::Vector2d(8.4, -6.2);  // vibration between frames
  MirrorCenterDetector det;
  const auto c = det.detect(p.image, prior);
  ASSERT_TRUE(c.has_value());
  EXPECT_LE((c->center - p.circle.center).norm(), 0.3);
}

// detect()'s votes from the band's runs with Sobel computed per pixel, against OpenCV's Sobel
// of the band's square and a test of every pixel: the same centre and rim radius to the bit,
// with and without a mask, for priors off the true centre and rims cut by the image's sides.
TEST(MirrorCenter, FastVotesEqualThePlainReference) {
  cv::Mat usable(480, 640, CV_8U, cv::Scalar(255));
  cv::line(usable, {320, 240}, {620, 40}, cv::Scalar(0), 8);
  int compared = 0;
  for (std::uint64_t seed : {3, 5, 9}) {
    sim::RadialPatternOptions o;
    o.seed = seed;
    o.center_jitter = 40.0;  // rims cut by the top and bottom of the image
    auto p = sim::draw_radial_pattern(o);
    // Noise in a ring outside the rim, at the band's outer edge: votes from every part of
    // the band.
    cv::Mat noise(p.image.size(), CV_8U);
    cv::randu(noise, 0, 255);
    cv::Mat ring(p.image.size(), CV_8U, cv::Scalar(0));
    const cv::Point c(static_cast<int>(p.circle.center.x()), static_cast<int>(p.circle.center.y()));
    cv::circle(ring, c, static_cast<int>(p.circle.rim_radius + 24), cv::Scalar(255), cv::FILLED);
    cv::circle(ring, c, static_cast<int>(p.circle.rim_radius + 8), cv::Scalar(0), cv::FILLED);
    noise.copyTo(p.image, ring);
    for (const Eigen::Vector2d& shift :
         {Eigen::Vector2d(0.3, 0.2), Eigen::Vector2d(8.4, -6.2), Eigen::Vector2d(-11.7, 4.9)}) {
      for (bool masked : {false, true}) {
        MirrorCircle prior = p.circle;
        prior.center += shift;
        // The search every time (track_px 0), so that both vote.
        MirrorCenterOptions plain, searched;
        searched.track_px = 0;
        plain.track_px = 0;
        plain.reference = true;
        MirrorCenterDetector fast(searched), ref(plain);
        if (masked) {
          fast.set_mask(usable);
          ref.set_mask(usable);
        }
        const auto a = fast.detect(p.image, prior);
        const auto b = ref.detect(p.image, prior);
        ASSERT_TRUE(b.has_value());
        ASSERT_TRUE(a.has_value());
        EXPECT_EQ(a->center.x(), b->center.x());
        EXPECT_EQ(a->center.y(), b->center.y());
        EXPECT_EQ(a->rim_radius, b->rim_radius);
        EXPECT_LE((b->center - p.circle.center).norm(), 0.5);
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 18);
}

// Tracked from frame to frame: from a prior within a pixel, the rim fitted without the search
// finds the centre as well as the search does; from a prior 10 px off, the search takes over.
TEST(MirrorCenter, TrackingFromANearPriorIsAsGoodAsTheSearch) {
  MirrorCenterOptions searched;
  searched.track_px = 0;
  const MirrorCenterDetector tracked, search(searched);
  double worst_tracked = 0, worst_searched = 0;
  for (std::uint64_t seed : {2, 4, 6, 8}) {
    sim::RadialPatternOptions o;
    o.seed = seed;
    const auto p = sim::draw_radial_pattern(o);
    for (const Eigen::Vector2d& shift :
         {Eigen::Vector2d(0.4, -0.3), Eigen::Vector2d(-0.6, 0.5), Eigen::Vector2d(7.0, -7.0)}) {
      MirrorCircle prior = p.circle;
      prior.center += shift;
      const auto a = tracked.detect(p.image, prior);
      const auto b = search.detect(p.image, prior);
      ASSERT_TRUE(a.has_value() && b.has_value());
      worst_tracked = std::max(worst_tracked, (a->center - p.circle.center).norm());
      worst_searched = std::max(worst_searched, (b->center - p.circle.center).norm());
      EXPECT_NEAR(a->rim_radius, p.circle.rim_radius, 0.3);
    }
  }
  EXPECT_LE(worst_tracked, 0.05);
  EXPECT_LE(worst_tracked, worst_searched + 0.01);
  std::printf(
      "worst centre error: tracked %.3f px, searched %.3f px\n", worst_tracked, worst_searched);
}

}  // namespace
}  // namespace omnivert
