// Radial-line extraction on images drawn with edges at known angles (Sec. 2).

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/sim/radial_pattern.hpp"

namespace omnivert {
namespace {

struct Score {
  int long_edges = 0, long_found = 0, invented = 0;
  std::vector<double> errors_deg;
  std::vector<double> center_errors;
};

// Matches detections to truth within 0.3 degree.
void score_frame(const sim::RadialPattern& p, const FrameFeatures& f, Score& s) {
  const double L = p.circle.r_max - p.circle.r_min;
  s.center_errors.push_back((f.circle.center - p.circle.center).norm());
  for (const auto& e : p.edges) {
    if (e.r_to - e.r_from < 0.6 * L) continue;
    ++s.long_edges;
    double best = 1e9;
    for (const auto& l : f.lines) best = std::min(best, std::abs(angle_diff(l.image_angle, e.image_angle)));
    if (best <= deg2rad(0.3)) {
      ++s.long_found;
      s.errors_deg.push_back(rad2deg(best));
    }
  }
  for (const auto& l : f.lines) {
    double best = 1e9;
    for (const auto& e : p.edges) best = std::min(best, std::abs(angle_diff(l.image_angle, e.image_angle)));
    if (best > deg2rad(0.3)) ++s.invented;
  }
}

double rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return v.empty() ? 0 : std::sqrt(s / v.size());
}

TEST(LineExtractor, FindsEveryLongEdgeAtItsAngleAndInventsNone) {
  Score s;
  for (int seed = 1; seed <= 20; ++seed) {
    sim::RadialPatternOptions o;
    o.seed = seed;
    o.noise_sigma = 2.0 + (seed % 3);
    const auto p = sim::draw_radial_pattern(o);
    CameraGeometry g;
    g.width = o.width;
    g.height = o.height;
    FeaturePipeline pipe(g);
    FrameFeatures f;
    std::string why;
    ASSERT_TRUE(pipe.process(p.image, f, &why)) << why;
    score_frame(p, f, s);
  }
  const double center_rms = rms(s.center_errors);
  std::printf("long edges %d found %d invented %d bearing RMS %.4f deg centre RMS %.3f px\n",
              s.long_edges, s.long_found, s.invented, rms(s.errors_deg), center_rms);
  EXPECT_EQ(s.long_found, s.long_edges);
  EXPECT_EQ(s.invented, 0);
  EXPECT_LE(rms(s.errors_deg), 0.05);
  for (double e : s.center_errors) EXPECT_LE(e, 0.3);
}

}  // namespace
}  // namespace omnivert
