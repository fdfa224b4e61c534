// Mirror centre (Sec. 2 step 1) on drawn images with known centres.

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace omnivert
