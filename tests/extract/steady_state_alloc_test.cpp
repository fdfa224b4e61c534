// The edge stage allocates nothing per frame once warmed up (the steady state of a video): the
// lookup table is built once per annulus and every buffer is reused.

#include <gtest/gtest.h>

#include "../support/alloc_counter.hpp"
#include "omnivert/extract/line_extractor.hpp"
#include "omnivert/sim/radial_pattern.hpp"

namespace omnivert {
namespace {

TEST(LineExtractorSteadyState, NoAllocationPerFrame) {
  sim::RadialPatternOptions o;
  std::vector<sim::RadialPattern> frames;
  for (int seed = 1; seed <= 4; ++seed) {
    o.seed = seed;
    o.center_jitter = 0.4;  // vibration below a pixel: same rounded centre
    frames.push_back(sim::draw_radial_pattern(o));
  }
  LineExtractor ex;
  std::vector<VerticalLine> lines;
  lines.reserve(256);
  for (const auto& f : frames) ex.extract(f.image, f.circle, lines);  // warm up
  const long before = omnivert_test_allocations();
  std::size_t total = 0;
  for (int k = 0; k < 20; ++k) {
    const auto& f = frames[k % frames.size()];
    ex.extract(f.image, f.circle, lines);
    total += lines.size();
  }
  EXPECT_EQ(omnivert_test_allocations() - before, 0);
  EXPECT_GT(total, 200u);  // it did find lines
}

TEST(LineExtractorSteadyState, TheCounterSeesAllocations) {
  const long before = omnivert_test_allocations();
  std::vector<int> v(1000);
  v[3] = 1;
  EXPECT_GE(omnivert_test_allocations() - before, 1);
}

}  // namespace
}  // namespace omnivert
