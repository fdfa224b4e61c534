// Matching and track bookkeeping per frame (Sec. 4, 9.1), against OpenCV's brute-force
// matcher (NORM_L2, knnMatch k = 2) on the same descriptor sets, in the same run.
//
//   build/bench/match/match_bench --benchmark_repetitions=10
//       --benchmark_report_aggregates_only=true   (one command line)
//
// One benchmark iteration = one frame. Sequences: a world of 1.5 x N lines with paper-like
// 192-D descriptors, about N visible per frame (N = 20, 30, 40), each detection perturbed by
// noise, lines missed for a few frames (look-back exercised), lines coming and going.

#include <algorithm>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include "omnivert/match/matcher.hpp"
#include "omnivert/match/tracker.hpp"

namespace omnivert {
namespace {

constexpr int kFrames = 256;  // the sequence is cycled

Eigen::RowVectorXf random_descriptor(std::mt19937& rng) {
  std::exponential_distribution<float> e(1.0f);
  Eigen::RowVectorXf d(kPaperDescriptorSize);
  for (int k = 0; k < d.size(); ++k) d(k) = e(rng);
  d.normalize();
  d = d.cwiseMin(0.1f);
  d.normalize();
  return d;
}

std::vector<FrameFeatures> make_sequence(int lines_per_frame) {
  std::mt19937 rng(1234u + static_cast<unsigned>(lines_per_frame));
  const int world_size = lines_per_frame * 3 / 2;
  std::vector<Eigen::RowVectorXf> world;
  for (int w = 0; w < world_size; ++w) world.push_back(random_descriptor(rng));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  // Each world line is visible on a window of the cycle, and missed at random (8%).
  std::vector<int> start(world_size), len(world_size);
  for (int w = 0; w < world_size; ++w) {
    start[w] = static_cast<int>(u(rng) * kFrames);
    len[w] = static_cast<int>(kFrames * (0.5 + 0.35 * u(rng)));
  }
  std::vector<FrameFeatures> seq(kFrames);
  for (int f = 0; f < kFrames; ++f) {
    std::vector<int> visible;
    for (int w = 0; w < world_size; ++w) {
      const int age = (f - start[w] + kFrames) % kFrames;
      if (age < len[w] && u(rng) > 0.08) visible.push_back(w);
    }
    std::shuffle(visible.begin(), visible.end(), rng);
    FrameFeatures& fr = seq[static_cast<std::size_t>(f)];
    fr.descriptors.resize(static_cast<Eigen::Index>(visible.size()), kPaperDescriptorSize);
    for (std::size_t i = 0; i < visible.size(); ++i) {
      Eigen::RowVectorXf d = world[static_cast<std::size_t>(visible[i])];
      for (int k = 0; k < d.size(); ++k) d(k) = std::max(0.0f, d(k) + noise(rng));
      fr.descriptors.row(static_cast<Eigen::Index>(i)) = d.normalized();
      VerticalLine v;
      v.bearing = -3.0 + 6.0 * visible[i] / world_size;
      fr.lines.push_back(v);
    }
  }
  return seq;
}

void BM_TrackerPerFrame(benchmark::State& state) {
  const auto seq = make_sequence(static_cast<int>(state.range(0)));
  TrackerOptions o;  // paper: tests 1-3, look-back 20
  o.mutual = state.range(1) != 0;
  Tracker tracker(o);
  std::vector<TrackAssignment> out;
  // Warm up: fill the 20-frame ring buffer and the work spaces.
  for (int f = 0; f < 40; ++f) tracker.add_frame(seq[static_cast<std::size_t>(f)], &out);
  std::size_t f = 40, lines = 0;
  for (auto _ : state) {
    const FrameFeatures& fr = seq[f % kFrames];
    tracker.add_frame(fr, &out);
    benchmark::DoNotOptimize(out.data());
    lines += fr.lines.size();
    ++f;
  }
  const auto& s = tracker.stats();
  state.counters["lines/frame"] =
      static_cast<double>(lines) / static_cast<double>(std::max<std::size_t>(1, f - 40));
  state.counters["look-back%"] =
      100.0 * static_cast<double>(s.matched_look_back) / static_cast<double>(s.lines);
  state.counters["new%"] = 100.0 * static_cast<double>(s.new_tracks) / static_cast<double>(s.lines);
}
BENCHMARK(BM_TrackerPerFrame)
    ->ArgNames({"lines", "mutual"})
    ->ArgsProduct({{20, 30, 40}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

// The recommended rule sets with wheel data (straight driving, 3.8 cm a frame): mutual, gate,
// same polarity and track continuity. variant 0: the link model at 1 degree with the paper's
// F1 (an earlier recommended set); 1: the track model at 0.8 degree
// with F1 0.6 and look-back F1 0.5 (recommended now); 2: 1 + heads_only.
void BM_TrackerRecommended(benchmark::State& state) {
  const auto seq = make_sequence(static_cast<int>(state.range(0)));
  TrackerOptions o = recommended_tracker_options(0.4);
  if (state.range(1) == 0) {
    o.continuity_model = TrackerOptions::ContinuityModel::kLink;
    o.continuity_tolerance = 1.0 * 3.14159265358979323846 / 180.0;
    o.match.f1 = 1.05;
    o.look_back_f1 = 0.0;
  }
  o.heads_only = state.range(1) == 2;
  Tracker tracker(o);
  std::vector<TrackAssignment> out;
  const WheelIncrement straight{0.038, 0.038};
  for (int f = 0; f < 40; ++f) tracker.add_frame(seq[static_cast<std::size_t>(f)], straight, &out);
  std::size_t f = 40, lines = 0;
  for (auto _ : state) {
    const FrameFeatures& fr = seq[f % kFrames];
    tracker.add_frame(fr, straight, &out);
    benchmark::DoNotOptimize(out.data());
    lines += fr.lines.size();
    ++f;
  }
  const auto& s = tracker.stats();
  state.counters["lines/frame"] =
      static_cast<double>(lines) / static_cast<double>(std::max<std::size_t>(1, f - 40));
  state.counters["look-back%"] =
      100.0 * static_cast<double>(s.matched_look_back) / static_cast<double>(s.lines);
}
BENCHMARK(BM_TrackerRecommended)
    ->ArgNames({"lines", "variant"})
    ->ArgsProduct({{20, 30, 40}, {0, 1, 2}})
    ->Unit(benchmark::kMicrosecond);

// Our matcher alone, one frame against the previous one (tests 1-3 included); "partial" 1: the
// occluder-tolerant distance (MatchOptions::partial_area_scale 2: three products, one per
// circle of the descriptor).
void BM_MatcherPreviousFrame(benchmark::State& state) {
  const auto seq = make_sequence(static_cast<int>(state.range(0)));
  MatchOptions o;
  o.partial_area_scale = state.range(1) == 1 ? 2.0 : 0.0;
  Matcher m(o);
  std::vector<MatchResult> results;
  std::size_t f = 1;
  for (auto _ : state) {
    m.match(seq[f % kFrames].descriptors, seq[(f - 1) % kFrames].descriptors, &results);
    benchmark::DoNotOptimize(results.data());
    ++f;
  }
}
BENCHMARK(BM_MatcherPreviousFrame)
    ->ArgNames({"lines", "partial"})
    ->ArgsProduct({{20, 30, 40}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

// The peer: cv::BFMatcher(NORM_L2).knnMatch(k = 2) of one frame against the previous one,
// on the same descriptors (wrapped as cv::Mat without copying). It gives the two nearest
// distances only, not the mean of test 2 nor any bookkeeping.
void BM_CvBFMatcherKnn2PreviousFrame(benchmark::State& state) {
  const auto seq = make_sequence(static_cast<int>(state.range(0)));
  std::vector<cv::Mat> mats;
  for (const auto& fr : seq) {
    mats.emplace_back(static_cast<int>(fr.descriptors.rows()),
                      static_cast<int>(fr.descriptors.cols()),
                      CV_32F,
                      const_cast<float*>(fr.descriptors.data()));
  }
  cv::BFMatcher matcher(cv::NORM_L2);
  std::vector<std::vector<cv::DMatch>> knn;
  std::size_t f = 1;
  for (auto _ : state) {
    matcher.knnMatch(mats[f % kFrames], mats[(f - 1) % kFrames], knn, 2);
    benchmark::DoNotOptimize(knn.data());
    ++f;
  }
}
BENCHMARK(BM_CvBFMatcherKnn2PreviousFrame)
    ->ArgName("lines")
    ->Arg(20)
    ->Arg(30)
    ->Arg(40)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace omnivert
