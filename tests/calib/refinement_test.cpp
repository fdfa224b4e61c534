// The batch refinement's answer (refinement.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <Eigen/Dense>

#include "calib/batch_point.hpp"
#include "calib/synthetic_run.hpp"
#include "omnivert/calib/calibrate.hpp"
#include "omnivert/calib/refinement.hpp"
#include "omnivert/core/angles.hpp"
#include "synthetic_support.hpp"

namespace omnivert::calib {
namespace {

using test_support::nees;
using test_support::options_for;
using test_support::refined;
using test_support::truth_point;

TEST(Refinement, MirroredExtrinsicsAreReportedWithPositiveRho) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.05);
  so.seed = 3;
  const SyntheticRun run = make_synthetic_run(so);
  BatchPoint start = truth_point(run);
  start.extrinsics = {run.truth.phi + kPi, -run.truth.rho, run.truth.psi - kPi};
  const RefinementResult r = refine_batch(run.run, options_for(so), start);
  ASSERT_TRUE(r.covariance_ok);
  EXPECT_GT(r.extrinsics.rho, 0.0);
  EXPECT_NEAR(r.extrinsics.rho, run.truth.rho, 0.01);
  EXPECT_NEAR(wrap_angle(r.extrinsics.phi - run.truth.phi), 0.0, deg2rad(2.0));
  EXPECT_NEAR(wrap_angle(r.extrinsics.psi - run.truth.psi), 0.0, deg2rad(2.0));
  EXPECT_LT(nees(r, run.truth), 16.3);
  const RefinementResult direct = refine_batch(run.run, options_for(so), truth_point(run));
  EXPECT_NEAR(r.extrinsics.rho, direct.extrinsics.rho, 1e-6);
  EXPECT_NEAR(std::sqrt(r.covariance(1, 1)), std::sqrt(direct.covariance(1, 1)), 1e-6);
}

// The result's reports: the brief one gives phi, rho, psi with their sigmas as documented
// (degrees with 3 decimals, millimetres with 2) and the verdict; the full one every stage.
TEST(CalibrationResult, ReportsGiveTheEstimateItsSigmasAndTheVerdict) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.05);
  so.seed = 3;
  const SyntheticRun run = make_synthetic_run(so);
  const CalibrationResult r = calibrate(run.run, refined(options_for(so)));
  ASSERT_TRUE(r.refined && r.refinement.covariance_ok && r.observable());
  char line[256];
  std::snprintf(
      line,
      sizeof line,
      "refined estimate: phi %.3f +- %.3f deg, rho %.2f +- %.2f mm, psi %.3f +- %.3f deg\n",
      rad2deg(r.extrinsics.phi),
      rad2deg(std::sqrt(r.covariance(0, 0))),
      1e3 * r.extrinsics.rho,
      1e3 * std::sqrt(r.covariance(1, 1)),
      rad2deg(r.extrinsics.psi),
      rad2deg(std::sqrt(r.covariance(2, 2))));
  const std::string brief = r.BriefReport();
  EXPECT_EQ(brief.rfind(line, 0), 0u) << brief;
  EXPECT_NE(brief.find(r.observability.message), std::string::npos) << brief;
  EXPECT_NE(brief.find("camera in the robot frame: x "), std::string::npos) << brief;
  const std::string full = r.FullReport();
  EXPECT_EQ(full.rfind(brief, 0), 0u);  // begins with the brief report
  for (const char* item : {"\nfilter: phi ",
                           "\nrefinement: phi ",
                           "\nCramer-Rao bound: phi ",
                           "\nbearing noise model: 0.050 deg\n",
                           "\nnoise check: over ",
                           "\nrefinement: converged",
                           "\ntime: filter "})
    EXPECT_NE(full.find(item), std::string::npos) << item << " in\n" << full;
}

// CalibrationOptions::progress: every stage reported in order on the calling thread (the
// filter's noise check, beside the refinement on a second thread, reports nothing), and the
// results are those of a run without it, to the bit.
TEST(Progress, EachStageOnTheCallingThreadAndTheSameResults) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.05);
  so.break_probability = 0.1;  // pieces of lines for the joining rounds
  so.seed = 5;
  const SyntheticRun run = make_synthetic_run(so);
  const std::size_t n = run.run.frames.size();
  CalibrationOptions o = refined(options_for(so));
  o.refinement.warm_start_window = 30;  // a few windows on a short run
  o.refinement.warm_start_overlap = 10;
  o.threads = 2;
  const CalibrationResult plain = calibrate(run.run, o);
  std::vector<std::tuple<std::string, std::size_t, std::size_t>> seen;
  bool other_thread = false;
  const std::thread::id caller = std::this_thread::get_id();
  o.progress = [&](const std::string& stage, std::size_t done, std::size_t total) {
    if (std::this_thread::get_id() != caller) {
      other_thread = true;
      return;
    }
    seen.emplace_back(stage, done, total);
  };
  const CalibrationResult reported = calibrate(run.run, o);
  EXPECT_FALSE(other_thread);
  EXPECT_EQ(reported.extrinsics.phi, plain.extrinsics.phi);
  EXPECT_EQ(reported.extrinsics.rho, plain.extrinsics.rho);
  EXPECT_EQ(reported.extrinsics.psi, plain.extrinsics.psi);
  EXPECT_EQ(reported.covariance, plain.covariance);
  // The filter's frames one by one, then the refinement's stages in order.
  std::vector<std::string> order;
  std::size_t filter_frames = 0, windows = 0, window_total = 0, join_rounds = 0;
  for (const auto& [stage, done, total] : seen) {
    if (order.empty() || order.back() != stage) order.push_back(stage);
    if (stage == "filter") {
      EXPECT_EQ(done, ++filter_frames);
      EXPECT_EQ(total, n);
    } else if (stage == "refinement: warm start") {
      EXPECT_EQ(done, ++windows);
      window_total = total;
    } else if (stage == "refinement: joining pieces") {
      EXPECT_EQ(done, ++join_rounds);
      EXPECT_EQ(total, 0u);
    }
  }
  EXPECT_EQ(filter_frames, n);
  // Windows start every 20 frames until one reaches the end.
  EXPECT_EQ(window_total, (n - 30 + 19) / 20 + 1);
  EXPECT_EQ(windows, window_total);
  EXPECT_GE(join_rounds, 2u) << "the synthetic breaks leave pieces to join";
  const std::vector<std::string> expected = {"filter",
                                             "refinement: warm start",
                                             "refinement: first solve",
                                             "refinement: joining pieces",
                                             "refinement: splitting tracks",
                                             "refinement: covariance"};
  EXPECT_EQ(order, expected);
}

}  // namespace
}  // namespace omnivert::calib
