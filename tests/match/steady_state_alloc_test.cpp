// The tracker allocates nothing per frame in steady state (buffers grow to the largest frame
// and are reused). Allocations are counted by tests/support/alloc_counter.cpp.

#include <cstddef>
#include <random>

#include <gtest/gtest.h>

#include "../support/alloc_counter.hpp"
#include "omnivert/match/tracker.hpp"

namespace omnivert {
namespace {

TEST(TrackerSteadyState, NoAllocationPerFrame) {
  std::mt19937 rng(5);
  std::exponential_distribution<float> e(1.0f);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int world = 45;
  DescriptorMatrix base(world, kPaperDescriptorSize);
  for (int w = 0; w < world; ++w) {
    for (int k = 0; k < kPaperDescriptorSize; ++k) base(w, k) = e(rng);
    base.row(w).normalize();
  }
  // 60 frames of 20-40 lines (some missed, so the look-back runs), prepared up front.
  std::vector<FrameFeatures> frames(60);
  for (auto& f : frames) {
    std::vector<int> vis;
    for (int w = 0; w < world; ++w) {
      if (u(rng) < 0.75) vis.push_back(w);
    }
    f.descriptors.resize(static_cast<Eigen::Index>(vis.size()), kPaperDescriptorSize);
    for (std::size_t i = 0; i < vis.size(); ++i) {
      for (int k = 0; k < kPaperDescriptorSize; ++k) {
        f.descriptors(static_cast<Eigen::Index>(i), k) = base(vis[i], k) + noise(rng);
      }
      f.lines.push_back(VerticalLine{});
    }
  }
  for (bool mutual : {false, true}) {
    TrackerOptions o;
    o.mutual = mutual;
    o.gate.enabled = true;
    o.gate.wheel_base = 0.5;
    Tracker tracker(o);
    std::vector<TrackAssignment> out;
    out.reserve(64);
    const WheelIncrement inc{0.03, 0.02};
    // Warm-up: the largest frame and a full ring buffer.
    for (int f = 0; f < 30; ++f) tracker.add_frame(frames[static_cast<std::size_t>(f)], inc, &out);
    const long before = omnivert_test_allocations();
    for (int f = 30; f < 60; ++f) tracker.add_frame(frames[static_cast<std::size_t>(f)], inc, &out);
    const long during = omnivert_test_allocations() - before;
    EXPECT_EQ(during, 0) << "mutual=" << mutual;
    EXPECT_GT(tracker.stats().matched_look_back, 0);  // the look-back path was exercised
  }
  // The counter works.
  const long before = omnivert_test_allocations();
  std::vector<int>* v = new std::vector<int>(100);
  delete v;
  EXPECT_GE(omnivert_test_allocations() - before, 2);
}

}  // namespace
}  // namespace omnivert
