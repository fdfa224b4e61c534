// An extreme frame (docs/validation.md#hostile-and-extreme-inputs): 500 radial edges drawn at
// known angles in one 2000x2000 image, extracted (Sec. 2), described (Sec. 3) and tracked into the
// same scene rotated by 0.2 degree (Sec. 4). Every stage handles the crowd: at least half the edges
// are found at their angle, at most 5 % of the lines are invented, the descriptors are finite, and
// the tracker links most lines of the second frame to the right line of the first.

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/match/tracker.hpp"
#include "omnivert/sim/radial_pattern.hpp"

namespace omnivert {
namespace {

// Angle of the nearest true edge to a, in degrees.
double nearest_deg(const sim::RadialPattern& p, double a) {
  double best = 1e9;
  for (const auto& e : p.edges) best = std::min(best, std::abs(angle_diff(a, e.image_angle)));
  return rad2deg(best);
}

TEST(ManyLines, FiveHundredEdgesInOneFrameAreExtractedDescribedAndTracked) {
  sim::RadialPatternOptions o;
  o.width = o.height = 2000;
  o.r_min = 300;
  o.r_max = 950;
  o.rim_radius = 960;
  o.center_jitter = 0;
  o.full_edges = 500;
  o.patches = 0;
  o.min_separation_deg = 0.12;  // full edges keep 3x this apart: 500 of them fit
  o.min_contrast = 60;
  o.noise_sigma = 2.0;
  const sim::RadialPattern first = sim::draw_radial_pattern(o);
  ASSERT_EQ(first.edges.size(), 500u);
  o.rotation_rad = deg2rad(0.2);
  const sim::RadialPattern second = sim::draw_radial_pattern(o);

  CameraGeometry g;
  g.width = o.width;
  g.height = o.height;
  g.center = first.circle.center;
  g.r_min = o.r_min;
  g.r_max = o.r_max;
  FeaturePipeline pipe(g);
  FrameFeatures f1, f2;
  std::string why;
  ASSERT_TRUE(pipe.process(first.image, f1, &why)) << why;
  ASSERT_TRUE(pipe.process(second.image, f2, &why)) << why;

  int invented = 0;
  for (const auto& l : f1.lines) invented += nearest_deg(first, l.image_angle) > 0.3;
  RecordProperty("lines_found", static_cast<int>(f1.lines.size()));
  EXPECT_GE(f1.lines.size(), 250u);
  EXPECT_LE(f1.lines.size(), 500u);
  EXPECT_LE(invented, static_cast<int>(f1.lines.size()) / 20);
  ASSERT_EQ(static_cast<std::size_t>(f1.descriptors.rows()), f1.lines.size());
  EXPECT_TRUE(f1.descriptors.allFinite());

  Tracker tracker(TrackerOptions{});
  std::vector<TrackAssignment> a1, a2;
  tracker.add_frame(f1, &a1);
  tracker.add_frame(f2, &a2);
  ASSERT_EQ(a2.size(), f2.lines.size());
  // A link is right when the matched line of frame 1 lies 0.2 degree before this one.
  int linked = 0, right = 0;
  for (std::size_t i = 0; i < a2.size(); ++i) {
    if (a2[i].matched_line < 0) continue;
    ++linked;
    const double moved =
        rad2deg(angle_diff(f2.lines[i].image_angle,
                           f1.lines[static_cast<std::size_t>(a2[i].matched_line)].image_angle));
    right += std::abs(moved - 0.2) < 0.15;
  }
  RecordProperty("linked", linked);
  RecordProperty("linked_right", right);
  EXPECT_GE(linked, static_cast<int>(f2.lines.size()) / 2);
  EXPECT_GE(right, linked * 85 / 100);  // measured: 358 of 400
}

}  // namespace
}  // namespace omnivert
