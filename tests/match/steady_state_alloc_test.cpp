// The tracker allocates nothing per frame in steady state (buffers grow to the largest frame
// and are reused). Counted by replacing malloc in this test executable (glibc supports
// replacing malloc, calloc, realloc, free and the aligned variants; each forwards to glibc's
// own __libc_* entry points). Eigen and std::vector both allocate through malloc here.

#include <atomic>
#include <cstddef>
#include <random>

#include <gtest/gtest.h>

#include "omnivert/match/tracker.hpp"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);
}

namespace {
std::atomic<long> g_allocations{0};
}

extern "C" {
void* malloc(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(std::size_t k, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(k, n);
}
void* realloc(void* p, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
void* memalign(std::size_t a, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(a, n);
}
void* aligned_alloc(std::size_t a, std::size_t n) { return memalign(a, n); }
int posix_memalign(void** out, std::size_t a, std::size_t n) {
  void* p = memalign(a, n);
  if (!p) return 12;  // ENOMEM
  *out = p;
  return 0;
}
}

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
    const long before = g_allocations.load();
    for (int f = 30; f < 60; ++f) tracker.add_frame(frames[static_cast<std::size_t>(f)], inc, &out);
    const long during = g_allocations.load() - before;
    EXPECT_EQ(during, 0) << "mutual=" << mutual;
    EXPECT_GT(tracker.stats().matched_look_back, 0);  // the look-back path was exercised
  }
  // The counter works.
  const long before = g_allocations.load();
  std::vector<int>* v = new std::vector<int>(100);
  delete v;
  EXPECT_GE(g_allocations.load() - before, 2);
}

}  // namespace
}  // namespace omnivert
