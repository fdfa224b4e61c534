// The observability analysis of Sec. 8.1 (analyse_observability: the batch problem built at a
// point, its Fisher information, the marginal information of (phi, rho, psi) and the verdicts)
// at several run lengths: the sparse path grows linearly with the run, the dense reference
// (the whole nuisance block eigen-decomposed) cubically.
//
//   build/bench/calib/observability_bench --benchmark_repetitions=3
//       --benchmark_report_aggregates_only=true   (one command line)
//
// Runs: synthetic zigzags (calib/synthetic_run.hpp) of 50 frames per leg (24 straight, a
// 90-degree turn), 20 lines seen in every frame, each track broken with probability 0.05 per
// frame (tracks of 20 frames on average, as a tracker's that lose their lines): the bearings
// and tracks per frame stay the same whatever the length. Reported: time per frame
// (us_per_frame) and the fitted complexity.

#include <algorithm>
#include <cstdint>

#include <benchmark/benchmark.h>

#include "calib/batch_point.hpp"
#include "calib/synthetic_run.hpp"
#include "omnivert/calib/observability.hpp"

namespace omnivert::calib {
namespace {

struct Setup {
  SyntheticRun run;
  CalibrationOptions options;
  BatchPoint at;
};

Setup make_setup(int frames, bool dense) {
  SyntheticRunOptions so;
  so.trajectory = Trajectory::kZigzag;
  so.zigzag_legs = std::max(1, frames / 50);
  so.straight_length = so.zigzag_legs * 24 * so.step;
  so.num_features = 20;
  so.break_probability = 0.05;
  so.bearing_sigma = 0.025 * 3.14159265358979323846 / 180.0;
  Setup s{make_synthetic_run(so), {}, {}};
  s.options.robot.wheel_base = so.wheel_base;
  s.options.robot.odometry_K = so.odometry_K;
  s.options.noise.bearing_sigma = so.bearing_sigma;
  s.options.observability.dense_reference = dense;
  s.at.poses = s.run.true_poses;
  s.at.extrinsics = s.run.truth;
  for (const auto& [id, j] : s.run.track_feature) s.at.features[id] = s.run.features[j];
  return s;
}

void run_analysis(benchmark::State& state, bool dense) {
  const Setup s = make_setup(static_cast<int>(state.range(0)), dense);
  const auto frames = static_cast<double>(s.run.run.frames.size());
  for (auto _ : state) {
    ObservabilityReport r = analyse_observability(s.run.run, s.options, s.at);
    benchmark::DoNotOptimize(r);
  }
  state.SetComplexityN(static_cast<std::int64_t>(frames));
  state.counters["frames"] = frames;
  state.counters["us_per_frame"] = benchmark::Counter(
      frames * 1e-6, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_ObservabilitySparse(benchmark::State& state) { run_analysis(state, false); }
void BM_ObservabilityDense(benchmark::State& state) { run_analysis(state, true); }

BENCHMARK(BM_ObservabilitySparse)
    ->Arg(250)
    ->Arg(500)
    ->Arg(1000)
    ->Arg(2000)
    ->Arg(4000)
    ->Arg(8000)
    ->Unit(benchmark::kMillisecond)
    ->Complexity(benchmark::oN);
// The plain reference, where it is affordable.
BENCHMARK(BM_ObservabilityDense)
    ->Arg(250)
    ->Arg(500)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond)
    ->Complexity(benchmark::oNCubed);

}  // namespace
}  // namespace omnivert::calib
