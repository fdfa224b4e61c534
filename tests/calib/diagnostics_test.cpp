// Checks of the model by the data (diagnostics.hpp): the noise check and its verdicts, the
// wheel check, and the warnings calibrate() gives from them (result_warnings).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include <Eigen/Dense>
#include <string>

#include "calib/batch_point.hpp"
#include "calib/synthetic_run.hpp"
#include "omnivert/calib/calibrate.hpp"
#include "omnivert/calib/diagnostics.hpp"
#include "omnivert/calib/refinement.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/pipeline/calibration_report.hpp"
#include "synthetic_support.hpp"

namespace omnivert::calib {
namespace {

using test_support::options_for;
using test_support::refined;
using test_support::truth_point;

// result_warnings: a filter that refused many bearings, and a refinement outside the filter's
// 99.9% ellipsoid, are told; a consistent pair is not.
TEST(ResultWarnings, DivergenceAndDisagreementAreTold) {
  CalibrationResult r;
  r.filter.extrinsics = {-0.34, 0.23, 0.33};
  r.filter.covariance = Eigen::Vector3d(1e-4, 1e-6, 1e-4).asDiagonal();  // sigmas 0.57 deg, 1 mm
  for (int k = 0; k < 10; ++k) {
    FrameEstimate h;
    h.num_updates = 8;
    h.num_rejected = 2;  // 20%: not more than 20%
    r.filter.history.push_back(h);
  }
  EXPECT_TRUE(result_warnings(r).empty());
  r.filter.history[0].num_rejected = 3;
  std::vector<std::string> w = result_warnings(r);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("refused 21 of 101 bearings"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("--refine"), std::string::npos);
  r.filter.history[0].num_rejected = 2;
  r.refined = true;
  r.refinement.covariance_ok = true;
  r.refinement.extrinsics = {-0.34 + 0.02, 0.23 + 0.002, 0.33 - 0.02};  // (2 + 2 + 4) = 8
  EXPECT_TRUE(result_warnings(r).empty());
  r.refinement.extrinsics = {-0.34 + 0.03, 0.23 + 0.003, 0.33 - 0.03};  // 9 + 9 + 9 = 27
  w = result_warnings(r);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("disagree (squared Mahalanobis distance 27.0"), std::string::npos) << w[0];
  // Angles wrap: the same pair two turns apart is no disagreement.
  r.refinement.extrinsics = {-0.34 + 4 * kPi, 0.23, 0.33 - 2 * kPi};
  EXPECT_TRUE(result_warnings(r).empty());
}

// The data's own check of the bearing noise (RefinementResult::noise, the cluster-robust
// covariance with each track as a cluster). Monte Carlo over synthetic paper runs refined
// from the truth; returns the mean scale and the mean NEES with the model's and with the
// checked covariance.
struct NoiseCheckStats {
  double scale = 0, nees_model = 0, nees_checked = 0;
  int runs = 0;
};

NoiseCheckStats noise_check_monte_carlo(double true_sigma_deg,
                                        double correlation,
                                        int runs,
                                        double gate_probability = 0.999,
                                        double split_chi2 = AssociationOptions{}.split_chi2) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(true_sigma_deg);
  so.bearing_correlation = correlation;
  CalibrationOptions o = options_for(so);
  o.noise.bearing_sigma = deg2rad(0.05);  // what the model assumes
  o.association.gate_probability = gate_probability;
  o.association.split_chi2 = split_chi2;
  NoiseCheckStats s;
  for (int k = 0; k < runs; ++k) {
    so.seed = 300 + k;
    const SyntheticRun run = make_synthetic_run(so);
    const RefinementResult r = refine_batch(run.run, o, truth_point(run));
    if (!r.noise.ok) continue;
    ++s.runs;
    s.scale += r.noise.scale;
    s.nees_model += test_support::nees(r.extrinsics, r.noise.model_covariance, run.truth);
    s.nees_checked += test_support::nees(r.extrinsics, r.noise.covariance, run.truth);
  }
  s.scale /= s.runs;
  s.nees_model /= s.runs;
  s.nees_checked /= s.runs;
  return s;
}

// Independent bearings at the assumed sigma: the check agrees with the model (scale near 1;
// 50 runs: mean 0.94), and the model covariance it builds on is the Ceres one.
// The wheel check (WheelCheck): over 20 runs whose wheels follow their model, the statistic
// averages about chi-square(2)'s 2 and the rotation scale about 0; a model whose wheel base is
// 2% short (the wheels' turns read 2% too large) is found in every run, with the scale 0.02
// within 3 sigma, and told with the wheel base that fits.
TEST(WheelCheck, FindsAWrongWheelBaseAndNothingWhereTheModelIsRight) {
  double chi2 = 0.0, scale = 0.0;
  int runs = 0, flagged = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    SyntheticRunOptions so;
    so.bearing_sigma = deg2rad(0.03);
    so.seed = seed;
    const SyntheticRun run = make_synthetic_run(so);
    CalibrationOptions o = options_for(so);
    o.noise.bearing_sigma = so.bearing_sigma;
    const RefinementResult r = refine_batch(run.run, o, truth_point(run));
    ASSERT_TRUE(r.noise.wheels.ok) << seed;
    chi2 += r.noise.wheels.chi2;
    scale += r.noise.wheels.rotation_scale;
    flagged += wheel_check_rejects_model(r.noise.wheels);
    ++runs;
    if (seed > 5) continue;
    CalibrationOptions wrong = o;
    wrong.robot.wheel_base = so.wheel_base / 1.02;
    const RefinementResult w = refine_batch(run.run, wrong, truth_point(run));
    ASSERT_TRUE(w.noise.wheels.ok);
    EXPECT_TRUE(wheel_check_rejects_model(w.noise.wheels))
        << seed << ": chi2 " << w.noise.wheels.chi2;
    EXPECT_NEAR(w.noise.wheels.rotation_scale, 0.02, 3.0 * w.noise.wheels.sigma_rotation_scale)
        << seed;
    if (seed == 1) {
      CalibrationResult cr;
      cr.refined = true;
      cr.refinement = w;
      bool told = false;
      for (const std::string& m : result_warnings(cr))
        told |= m.find("turns 2.") != std::string::npos &&
                m.find("% larger than the robot made") != std::string::npos &&
                m.find("a wheel base of 0.5") != std::string::npos;
      EXPECT_TRUE(told);
    }
  }
  EXPECT_GT(chi2 / runs, 1.0);
  EXPECT_LT(chi2 / runs, 3.5);
  // One run's sigma of the scale is 0.25%; the mean over these runs is +0.14% (the wheels pull
  // the solution's poses a little: WheelCheck). Regressed on the wheels' own rotation it was
  // -0.22%.
  EXPECT_LT(std::abs(scale / runs), 0.002);
  EXPECT_LE(flagged, 1);
}

// Each side of the verdict at its own level: chi-square(10) / 10 has its 1% point at 0.256,
// its 30% point at 0.727 and its 99% point at 2.321.
TEST(NoiseCheck, VerdictSidesHaveTheirOwnLevels) {
  EXPECT_NEAR(noise_check_lower_limit(10, 0.01), 0.2558, 1e-3);
  EXPECT_NEAR(noise_check_lower_limit(10, 0.3), 0.7267, 1e-3);
  EXPECT_NEAR(noise_check_limit(10, 0.01), 2.3209, 1e-3);
  BatchNoiseCheck c;
  c.ok = true;
  c.clusters = 10;
  c.scale = 0.5;
  EXPECT_EQ(noise_check_verdict(c), NoiseVerdict::kAgrees);
  EXPECT_EQ(noise_check_verdict(c, 0.01, 0.3), NoiseVerdict::kLessNoise);
  EXPECT_EQ(noise_check_verdict(c, 0.01, 0.0), NoiseVerdict::kAgrees);  // 0: the side is off
  EXPECT_EQ(noise_check_verdict(c, 0.01, 0.5), NoiseVerdict::kAgrees);  // not a test
  c.scale = 0.2;
  EXPECT_EQ(noise_check_verdict(c), NoiseVerdict::kLessNoise);
  c.scale = 2.4;
  EXPECT_EQ(noise_check_verdict(c, 0.01, 0.3), NoiseVerdict::kMoreNoise);
  EXPECT_EQ(noise_check_verdict(c, 0.001, 0.3), NoiseVerdict::kAgrees);  // 99.9% point 2.959
  c.clusters = 1;
  EXPECT_EQ(noise_check_verdict(c, 0.01, 0.3), NoiseVerdict::kAgrees);
}

TEST(NoiseCheck, AgreesWithTheModelWhenTheModelIsRight) {
  const NoiseCheckStats s = noise_check_monte_carlo(0.05, 0.0, 20);
  ASSERT_EQ(s.runs, 20);
  EXPECT_GT(s.scale, 0.7);
  EXPECT_LT(s.scale, 1.3);
  EXPECT_GT(s.nees_checked, 0.5 * s.nees_model);
  EXPECT_LT(s.nees_checked, 2.0 * s.nees_model);
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.05);
  so.seed = 5;
  const SyntheticRun run = make_synthetic_run(so);
  const RefinementResult r = refine_batch(run.run, options_for(so), truth_point(run));
  ASSERT_TRUE(r.noise.ok);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(r.noise.model_covariance(i, i), r.covariance(i, i), 1e-3 * r.covariance(i, i));
}

// With a constant bearing error per line in the data and in the model (CalibrationOptions::
// track_bias_sigma), the check counts each line's bias prior as a row of that line's cluster:
// the scale stays near 1 (without that row the bias was free and the scale read 656 on a run
// from pixels), and the dense and sparse leverages agree.
TEST(NoiseCheck, AgreesWithTheModelWithPerLineBias) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.03);
  so.track_bias_sigma = deg2rad(0.03);
  CalibrationOptions o = options_for(so);
  o.noise.bearing_sigma = so.bearing_sigma;
  o.noise.track_bias_sigma = so.track_bias_sigma;
  CalibrationOptions sparse = o;
  sparse.noise_check.dense_limit = 0;
  double scale = 0.0;
  const int runs = 20;
  for (int k = 0; k < runs; ++k) {
    so.seed = 300 + k;
    const SyntheticRun run = make_synthetic_run(so);
    const RefinementResult r = refine_batch(run.run, o, truth_point(run));
    ASSERT_TRUE(r.noise.ok) << so.seed;
    scale += r.noise.scale;
    if (k < 3) {
      const RefinementResult s = refine_batch(run.run, sparse, truth_point(run));
      ASSERT_TRUE(s.noise.ok);
      EXPECT_NEAR(r.noise.scale, s.noise.scale, 1e-6 * r.noise.scale);
    }
  }
  scale /= runs;
  RecordProperty("scale", std::to_string(scale));
  EXPECT_GT(scale, 0.7);
  EXPECT_LT(scale, 1.3);
}

// The warning that the filter's gate refused many bearings counts the frames after the
// start-up window only: the window's own outliers (counted in its frames) are no sign of a
// filter that diverged; where the window failed, the filter ran over those frames and they
// count.
TEST(ResultWarnings, GateRefusalsCountAfterTheWindow) {
  CalibrationResult r;
  r.filter.window_frames = 10;
  r.filter.history.resize(30);
  for (int k = 0; k < 10; ++k) r.filter.history[k].num_rejected = 20;  // the window's outliers
  for (int k = 10; k < 30; ++k) r.filter.history[k].num_updates = 10;
  auto warns = [](const CalibrationResult& c) {
    for (const std::string& m : result_warnings(c))
      if (m.find("chi-square gate refused") != std::string::npos) return true;
    return false;
  };
  EXPECT_FALSE(warns(r));  // 0 of 200 after the window
  r.filter.window_failure = "window solve failed";
  EXPECT_TRUE(warns(r));  // 200 of 400 over the whole run, the EKF's own
  r.filter.window_failure.clear();
  for (int k = 10; k < 30; ++k) r.filter.history[k].num_rejected = 4;  // 80 of 280
  EXPECT_TRUE(warns(r));
  for (int k = 10; k < 30; ++k) r.filter.history[k].num_rejected = 2;  // 40 of 240
  EXPECT_FALSE(warns(r));
}

// The dense inverse (small problems) and the sparse solves (large ones) give the same check.
TEST(NoiseCheck, DenseAndSparseLeverageAgree) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.05);
  so.bearing_correlation = 0.5;
  so.seed = 9;
  const SyntheticRun run = make_synthetic_run(so);
  CalibrationOptions sparse = options_for(so);
  sparse.noise_check.dense_limit = 0;
  const RefinementResult d = refine_batch(run.run, options_for(so), truth_point(run));
  const RefinementResult s = refine_batch(run.run, sparse, truth_point(run));
  ASSERT_TRUE(d.noise.ok);
  ASSERT_TRUE(s.noise.ok);
  EXPECT_EQ(d.noise.clusters, s.noise.clusters);
  EXPECT_NEAR(d.noise.scale, s.noise.scale, 1e-6 * d.noise.scale);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(
        d.noise.covariance(i, i), s.noise.covariance(i, i), 1e-6 * d.noise.covariance(i, i));
}

// A long track's (I - H_cc)^-1/2 r_c by the Lanczos iteration (NoiseCheckOptions::
// dense_track_limit) against the eigen-decomposition of H_cc: 10 lines each seen over the
// whole ~170-frame run, every track taken the long way; dense and sparse inverses.
TEST(NoiseCheck, LongTracksByLanczosEqualTheDecomposition) {
  for (const std::uint64_t seed : {3u, 9u}) {
    SyntheticRunOptions so;
    so.bearing_sigma = deg2rad(0.05);
    so.bearing_correlation = 0.5;
    so.seed = seed;
    const SyntheticRun run = make_synthetic_run(so);
    const RefinementResult exact = refine_batch(run.run, options_for(so), truth_point(run));
    ASSERT_TRUE(exact.noise.ok);
    for (const int dense_limit : {3000, 0}) {
      CalibrationOptions o = options_for(so);
      o.noise_check.dense_track_limit = 0;
      o.noise_check.dense_limit = dense_limit;
      const RefinementResult l = refine_batch(run.run, o, truth_point(run));
      ASSERT_TRUE(l.noise.ok);
      EXPECT_EQ(l.noise.clusters, exact.noise.clusters);
      EXPECT_NEAR(l.noise.scale, exact.noise.scale, 1e-8 * exact.noise.scale)
          << "seed " << seed << " dense_limit " << dense_limit;
      EXPECT_LT((l.noise.bearing_clustered - exact.noise.bearing_clustered).norm(),
                1e-8 * exact.noise.bearing_clustered.norm());
    }
  }
}

// Bearings twice as noisy as assumed: the variance is four times the model's. Without the
// outlier gate and the track splitting, whose thresholds are in assumed sigmas: at the
// default gate (3.3 sigmas) a tenth of these bearings would be cut off and the rest would
// look less noisy than they are (scale 2.0), and splitting would cut clean tracks (10 per run).
TEST(NoiseCheck, FindsBearingsNoisierThanAssumed) {
  const NoiseCheckStats s =
      noise_check_monte_carlo(0.10, 0.0, 20, /*gate_probability=*/1.0, /*split_chi2=*/0.0);
  ASSERT_EQ(s.runs, 20);
  EXPECT_GT(s.scale, 3.0);
  EXPECT_LT(s.scale, 5.3);
  EXPECT_GT(s.nees_model, 7.81);  // the model is overconfident by the factor 4
  // With 10 tracks the check's scale of one run is itself uncertain (about chi-square(12) /
  // 12), so the mean NEES under the checked covariance stays above 3 (measured 5.3 against
  // the model's 8.8).
  EXPECT_LT(s.nees_checked, 0.7 * s.nees_model);
  RecordProperty("scale", std::to_string(s.scale));
  RecordProperty("nees_model", std::to_string(s.nees_model));
  RecordProperty("nees_checked", std::to_string(s.nees_checked));
}

// Errors correlated along each track (AR(1), 0.9 from frame to frame), each bearing at the
// assumed sigma: the model, which takes them as independent, is overconfident (NEES 13.0);
// the check, which sums a track's errors before squaring them, much less (6.9: with 10 tracks
// one run's scale is itself uncertain).
TEST(NoiseCheck, FindsErrorsCorrelatedAlongTracks) {
  const NoiseCheckStats s = noise_check_monte_carlo(0.05, 0.9, 20);
  ASSERT_EQ(s.runs, 20);
  EXPECT_GT(s.nees_model, 7.81);
  EXPECT_GT(s.scale, 2.0);
  EXPECT_LT(s.nees_checked, 0.6 * s.nees_model);
  RecordProperty("scale", std::to_string(s.scale));
  RecordProperty("nees_model", std::to_string(s.nees_model));
  RecordProperty("nees_checked", std::to_string(s.nees_checked));
}

// Bearings four times less noisy than assumed (variance / 16), the case of a camera better
// than the default --bearing-sigma: the check finds less noise than the model assumes
// (NoiseVerdict::kLessNoise), says so and names the sigma the data want, and, the tracks being
// whole (no pieces joined), shrinks the bearings' share of the covariances. The camera's yaw
// phi + psi, which the bearings determine, then has about the right sigma (mean z^2 near 1
// instead of 0.21 under the model's). With the same bearings cut into pieces every ~10
// frames (CalibrationOptions::noise_check.lower_max_joins), the verdict is reported and the
// covariances kept.
TEST(NoiseCheck, FindsBearingsLessNoisyThanAssumed) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.0125);
  CalibrationOptions o = options_for(so);
  o.noise.bearing_sigma = deg2rad(0.05);  // what the model assumes
  const int runs = 12;
  int less = 0, filter_less = 0, kept_broken = 0, less_broken = 0;
  double scale = 0, yaw = 0, yaw_model = 0;
  auto yaw_z2 = [](const Extrinsics& est, const Eigen::Matrix3d& c, const Extrinsics& truth) {
    const double e = angle_diff(est.phi + est.psi, truth.phi + truth.psi);
    return e * e / (c(0, 0) + c(2, 2) + 2.0 * c(0, 2));
  };
  for (int k = 0; k < runs; ++k) {
    so.seed = 400 + static_cast<std::uint64_t>(k);
    so.break_probability = 0.0;
    const SyntheticRun run = make_synthetic_run(so);
    const CalibrationResult r = calibrate(run.run, refined(o));
    ASSERT_TRUE(r.noise_check.checked && r.refinement.covariance_ok) << "seed " << so.seed;
    scale += r.noise_check.check.scale;
    if (r.noise_check.verdict == NoiseVerdict::kLessNoise) {
      ++less;
      EXPECT_LT(r.noise_check.check.scale,
                noise_check_lower_limit(r.noise_check.check.clusters, r.noise_check.lower_level));
      EXPECT_TRUE(r.noise_check.applied);
      EXPECT_NE(pipeline::noise_check_line(r).find("less than the model assumes"),
                std::string::npos);
      EXPECT_NE(pipeline::noise_check_line(r).find("sigmas scaled by"), std::string::npos);
      EXPECT_NE(pipeline::noise_check_line(r).find("--bearing-sigma"), std::string::npos);
      // The bearings' share only, and only to the test's bound: the factor the test does not
      // reject, scale / limit, not the estimate `scale` (the full shrink is check.covariance -
      // check.model_covariance, the bearings' share times scale - 1).
      const BatchNoiseCheck& c = r.noise_check.check;
      const double bound = c.scale / noise_check_lower_limit(c.clusters, r.noise_check.lower_level);
      EXPECT_LT(c.scale, bound);
      EXPECT_LT(bound, 1.0);
      const Eigen::Matrix3d applied = r.refinement.covariance - c.model_covariance;
      const Eigen::Matrix3d expected =
          (c.covariance - c.model_covariance) * ((1.0 - bound) / (1.0 - c.scale));
      EXPECT_LT((applied - expected).norm(), 1e-9 * expected.norm());
      // The yaw's variance shrinks, and the whole stays positive definite.
      EXPECT_LT(r.refinement.covariance(0, 0) + r.refinement.covariance(2, 2) +
                    2.0 * r.refinement.covariance(0, 2),
                r.noise_check.refinement_model_covariance(0, 0) +
                    r.noise_check.refinement_model_covariance(2, 2) +
                    2.0 * r.noise_check.refinement_model_covariance(0, 2));
      EXPECT_EQ(Eigen::LLT<Eigen::Matrix3d>(r.refinement.covariance).info(), Eigen::Success);
    } else {
      EXPECT_EQ(r.refinement.covariance, r.noise_check.refinement_model_covariance);
    }
    if (r.noise_check.filter_verdict == NoiseVerdict::kLessNoise) {
      ++filter_less;
      EXPECT_TRUE(r.noise_check.filter_applied);
      EXPECT_EQ(Eigen::LLT<Eigen::Matrix3d>(r.filter.covariance).info(), Eigen::Success);
    }
    yaw += yaw_z2(r.refinement.extrinsics, r.refinement.covariance, run.truth);
    yaw_model +=
        yaw_z2(r.refinement.extrinsics, r.noise_check.refinement_model_covariance, run.truth);
    // The same bearings in pieces: kept.
    so.break_probability = 0.1;
    const SyntheticRun broken = make_synthetic_run(so);
    const CalibrationResult b = calibrate(broken.run, refined(o));
    ASSERT_TRUE(b.noise_check.checked && b.refinement.covariance_ok) << "seed " << so.seed;
    if (b.noise_check.verdict == NoiseVerdict::kLessNoise) {
      ++less_broken;
      EXPECT_GT(static_cast<double>(b.refinement.merges.size()),
                0.5 * b.noise_check.check.clusters);
      kept_broken += !b.noise_check.applied &&
                     b.refinement.covariance == b.noise_check.refinement_model_covariance;
      EXPECT_NE(pipeline::noise_check_line(b).find("pieces of lines were joined"),
                std::string::npos);
    }
  }
  scale /= runs;
  yaw /= runs;
  yaw_model /= runs;
  RecordProperty("scale", std::to_string(scale));
  RecordProperty("yaw_z2", std::to_string(yaw));
  RecordProperty("yaw_z2_model", std::to_string(yaw_model));
  RecordProperty("less_broken", std::to_string(less_broken));
  // Measured: 10 of 12 runs below the limit (chi-square(G) / G's 1% point, 0.26
  // for 10 tracks), the filter's check too in 10; scale 0.18 in the mean (the bearings'
  // variance is 1/16 of the model's; the rest is the check's spread over 10 tracks); the
  // yaw's mean squared normalised error 0.21 under the model, 0.74 under the covariance
  // shrunk to the check's bound (0.99 shrunk to its estimate: right here, where the bearings
  // are far better than assumed, and overconfident in the runs the test flags by chance).
  EXPECT_GE(less, 9);
  EXPECT_GE(filter_less, 9);
  EXPECT_LT(scale, 0.4);
  EXPECT_LT(yaw_model, 0.5);
  EXPECT_GT(yaw, 0.5);
  EXPECT_LT(yaw, 2.0);
  EXPECT_EQ(kept_broken, less_broken);
}

// The filter's noise check runs beside the refinement when a second thread is allowed
// (CalibrationOptions::threads): on tracks the tracker broke (the filter joins pieces, so the
// check is not the refinement's own), one thread and two give the same numbers to the bit.
TEST(NoiseCheck, BesideTheRefinementGivesTheSameNumbersAsAfterIt) {
  SyntheticRunOptions so;
  so.seed = 71;
  so.break_probability = 0.1;
  const SyntheticRun run = make_synthetic_run(so);
  CalibrationOptions o = refined(options_for(so));
  o.threads = 1;
  const CalibrationResult one = calibrate(run.run, o);
  o.threads = 2;
  const CalibrationResult two = calibrate(run.run, o);
  ASSERT_FALSE(one.filter.joins.empty());
  ASSERT_TRUE(one.noise_check.checked && one.noise_check.filter_check.ok);
  EXPECT_EQ(one.noise_check.filter_check.scale, two.noise_check.filter_check.scale);
  EXPECT_EQ(one.noise_check.filter_check.covariance, two.noise_check.filter_check.covariance);
  EXPECT_EQ(one.filter.covariance, two.filter.covariance);
  EXPECT_EQ(one.refinement.covariance, two.refinement.covariance);
  EXPECT_EQ(one.covariance, two.covariance);
  EXPECT_EQ(one.extrinsics.vec(), two.extrinsics.vec());
  o.threads = -1;
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("threads"), std::string::npos);
}

}  // namespace
}  // namespace omnivert::calib
