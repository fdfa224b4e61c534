// The refinement's estimate of the camera-odometry time offset with the extrinsics
// (RefinementOptions::estimate_time_offset, CalibrationRun::clock): the odometry factor with the
// wheels' motion composed between the shifted stamps equals compose_wheel_steps at no shift and
// its derivative in the shift the numerical one; on runs of the paper's shape (a straight, a
// turn in place, a straight) whose image stamps are late by S, the shift is recovered within
// its sigma, and over Monte-Carlo runs the sigma is the spread of the errors; a line seen once
// (a singular information) leaves the marginal as it was.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "calib/batch_factors.hpp"
#include "calib/batch_problem.hpp"
#include "omnivert/calib/model.hpp"
#include "omnivert/calib/refinement.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {
namespace {

constexpr double kWheelBase = 0.4, kK = 1e-5, kSigma = 4.363323e-4;  // 0.025 degree
const Extrinsics kTruth{-0.34, 0.23, 0.33};

// Piecewise-constant (speed, turn rate) segments: rest, 2.3 m at 0.114 m/s, a turn in place of
// 180 degrees at 0.3 rad/s, 1 m straight, rest (the simulator's paper trajectory and more).
// The motion changes on wheel samples: a change between two samples is a kink that the
// linear interpolation of the wheel travel cuts (up to omega x 5 ms of heading, three bearing
// sigmas here), the same in every run; with it the errors' mean square was 2.0 sigma^2 over
// the 40 runs below (mean -0.96 ms), without it 1.16 (mean -0.32 ms).
struct Segment {
  double v, omega, duration;
};
const std::vector<Segment> kDrive = {
    {0, 0, 1.0}, {0.114, 0, 20.18}, {0, kPi / 10.48, 10.48}, {0.114, 0, 8.78}, {0, 0, 1.0}};

// The true pose (x, y, theta) and distance at time t (exact: straights and turns in place).
Eigen::Vector4d pose_at(double t) {
  Eigen::Vector4d p = Eigen::Vector4d::Zero();
  double t0 = 0;
  for (const Segment& s : kDrive) {
    const double dt = std::clamp(t - t0, 0.0, s.duration);
    p(0) += s.v * dt * std::cos(p(2));
    p(1) += s.v * dt * std::sin(p(2));
    p(2) += s.omega * dt;
    p(3) += s.v * dt;
    t0 += s.duration;
  }
  return p;
}

struct TimedRun {
  CalibrationRun run;
  BatchPoint truth;  // poses at the frames' true times, features, extrinsics
};

// Wheels at 50 Hz with eq. (31)'s noise, images at 3 Hz stamped late by `late` [s], 12 lines
// 1.5-6 m away with the bearing noise kSigma; each frame's wheel motion composed over the
// samples between its recorded stamps (what the pipeline does with the offset not known).
TimedRun make_run(double late, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> unit;
  std::uniform_real_distribution<double> angle(-kPi, kPi), dist(1.5, 6.0);
  double total = 0;
  for (const Segment& s : kDrive) total += s.duration;
  auto clock = std::make_shared<WheelClock>();
  double right = 0, left = 0;
  Eigen::Vector4d before = pose_at(0);
  for (double t = 0; t <= total + 1e-9; t += 0.02) {
    const Eigen::Vector4d p = pose_at(t);
    const double dd = p(3) - before(3), dth = p(2) - before(2);
    const double dr = dd + 0.5 * kWheelBase * dth, dl = dd - 0.5 * kWheelBase * dth;
    right += dr + std::sqrt(kK * std::abs(dr)) * unit(rng);
    left += dl + std::sqrt(kK * std::abs(dl)) * unit(rng);
    before = p;
    clock->t.push_back(t);
    clock->right.push_back(right);
    clock->left.push_back(left);
  }
  TimedRun out;
  std::vector<Eigen::Vector2d> lines;
  for (int j = 0; j < 12; ++j) {
    const double a = angle(rng), d = dist(rng);
    lines.emplace_back(1.15 + d * std::cos(a), d * std::sin(a));
    out.truth.features[j] = lines.back();
  }
  out.truth.extrinsics = kTruth;
  const auto travel = [&](double t) {
    return Eigen::Vector2d(internal::travel_at(clock->t, clock->left, t, 0.0),
                           internal::travel_at(clock->t, clock->right, t, 0.0));
  };
  for (double t = 0.5; t < total - 0.5; t += 1.0 / 3.0) {
    const Eigen::Vector4d p = pose_at(t);
    out.truth.poses.emplace_back(p(0), p(1), p(2));
    clock->image_t.push_back(t + late);
    FrameInput f;
    if (clock->image_t.size() > 1) {
      const double a = clock->image_t[clock->image_t.size() - 2], b = clock->image_t.back();
      std::vector<Eigen::Vector2d> steps{travel(a)};
      for (std::size_t k = 0; k < clock->t.size(); ++k)
        if (clock->t[k] > a && clock->t[k] < b) steps.push_back(travel(clock->t[k]));
      steps.push_back(travel(b));
      const Eigen::Vector3d m = compose_wheel_steps(steps, kWheelBase, &f.covariance_per_K);
      f.d_right = m(0), f.d_left = m(1), f.lateral = m(2);
    }
    for (int j = 0; j < 12; ++j)
      f.observations.push_back(
          {j,
           bearing_from_geometry(out.truth.poses.back(), lines[j], kTruth) + kSigma * unit(rng)});
    out.run.frames.push_back(std::move(f));
  }
  // Frame 0 is the gauge: the poses relative to it.
  const Eigen::Vector3d p0 = out.truth.poses.front();
  const double c = std::cos(p0(2)), s = std::sin(p0(2));
  const auto to0 = [&](const Eigen::Vector2d& q) {
    const Eigen::Vector2d d = q - p0.head<2>();
    return Eigen::Vector2d(c * d(0) + s * d(1), -s * d(0) + c * d(1));
  };
  for (Eigen::Vector3d& p : out.truth.poses)
    p = {to0(p.head<2>())(0), to0(p.head<2>())(1), p(2) - p0(2)};
  for (auto& [id, f] : out.truth.features) f = to0(f);
  out.run.clock = clock;
  return out;
}

CalibrationOptions options() {
  CalibrationOptions o;
  o.robot.wheel_base = kWheelBase;
  o.robot.odometry_K = kK;
  o.noise.bearing_sigma = kSigma;
  o.refinement.enabled = true;
  o.refinement.estimate_time_offset = true;
  return o;
}

TEST(TimeOffsetRefinement, TheTimedFactorComposesTheWheelsAndItsSlopeIsTheNumericalOne) {
  const TimedRun r = make_run(0.04, 1);
  const WheelClock& c = *r.run.clock;
  for (std::size_t k : {10u, 60u, 66u, 67u, 100u}) {
    const FrameInput& f = r.run.frames[k];
    double m[3];
    internal::compose_between(c, c.image_t[k - 1], c.image_t[k], 0.0, kWheelBase, m);
    EXPECT_NEAR(m[0], f.d_right, 1e-12) << "frame " << k;
    EXPECT_NEAR(m[1], f.d_left, 1e-12) << "frame " << k;
    EXPECT_NEAR(m[2], f.lateral, 1e-12) << "frame " << k;
    // Autodiff's slope in dS against central differences, at a shift inside one segment of
    // the wheel samples on both ends (the pieces are smooth there).
    using Jet = ceres::Jet<double, 1>;
    const double at = 0.0123, h = 1e-7;
    Jet mj[3];
    internal::compose_between(c, c.image_t[k - 1], c.image_t[k], Jet(at, 0), kWheelBase, mj);
    double mp[3], mm[3];
    internal::compose_between(c, c.image_t[k - 1], c.image_t[k], at + h, kWheelBase, mp);
    internal::compose_between(c, c.image_t[k - 1], c.image_t[k], at - h, kWheelBase, mm);
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(mj[i].v[0], (mp[i] - mm[i]) / (2 * h), 1e-6) << "frame " << k << " output " << i;
  }
}

TEST(TimeOffsetRefinement, ShiftedStampsAreRecoveredWithinTheirSigma) {
  for (double late : {-0.08, 0.04}) {
    const TimedRun r = make_run(late, 7);
    BatchPoint start = r.truth;
    const RefinementResult res = refine_batch(r.run, options(), start);
    ASSERT_TRUE(res.time_offset_estimated);
    ASSERT_TRUE(std::isfinite(res.time_offset_sigma_s));
    EXPECT_LT(res.time_offset_sigma_s, 0.01);
    EXPECT_LT(std::abs(res.time_offset_s - late), 3 * res.time_offset_sigma_s)
        << "late " << late << ": " << res.time_offset_s << " +- " << res.time_offset_sigma_s;
  }
}

TEST(TimeOffsetRefinement, TheSigmaIsTheSpreadOfTheErrors) {
  // 40 runs, 20 ms late: the mean of ((dS - S) / sigma)^2 is 1 within its 99% interval for 40
  // chi-square(1) draws, [0.45, 1.8].
  double sum = 0;
  const int n = 40;
  for (int seed = 1; seed <= n; ++seed) {
    const TimedRun r = make_run(0.02, static_cast<std::uint32_t>(100 + seed));
    const RefinementResult res = refine_batch(r.run, options(), r.truth);
    ASSERT_TRUE(std::isfinite(res.time_offset_sigma_s)) << "seed " << seed;
    sum += std::pow((res.time_offset_s - 0.02) / res.time_offset_sigma_s, 2);
  }
  EXPECT_GT(sum / n, 0.45);
  EXPECT_LT(sum / n, 1.8);
}

TEST(TimeOffsetRefinement, TheSparseMarginalEqualsCeresCovariance) {
  // The fallback where ceres::Covariance gives up (marginal_with_time_offset) against
  // ceres::Covariance (dense SVD: the plain reference) on the same problem, at the solution.
  const TimedRun r = make_run(0.04, 3);
  const RefinementResult res = refine_batch(r.run, options(), r.truth);
  ASSERT_FALSE(res.renamed());
  internal::Built b = internal::build(r.run, options(), res.solution, false);
  Eigen::Matrix3d C;
  double v = 0;
  ASSERT_TRUE(internal::marginal_with_time_offset(&b, &C, &v));
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance cov(co);
  const double* ex = b.ex.data();
  const double* dS = b.time_offset.data();
  ASSERT_TRUE(cov.Compute({{ex, ex}, {dS, dS}}, b.problem.get()));
  double ref[9], ref_v = 0;
  cov.GetCovarianceBlock(ex, ex, ref);
  cov.GetCovarianceBlock(dS, dS, &ref_v);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(C(i, j), ref[3 * i + j], 1e-6 * std::sqrt(C(i, i) * C(j, j)));
  EXPECT_NEAR(v, ref_v, 1e-6 * ref_v);
}

TEST(TimeOffsetRefinement, ALineSeenOnceLeavesTheMarginalFinite) {
  // A line seen in one image only: one bearing for its two coordinates, so J^T J is singular
  // and its plain LDLT fails (as ceres::Covariance does), which left the offset without a
  // sigma. That bearing tells nothing of the rest (the line's position absorbs it), so the
  // marginal of the extrinsics and the offset is the run's without it.
  TimedRun r = make_run(0.04, 3);
  internal::Built without = internal::build(r.run, options(), r.truth, false);
  Eigen::Matrix3d ref;
  double ref_v = 0;
  ASSERT_TRUE(internal::marginal_with_time_offset(&without, &ref, &ref_v));
  const std::size_t k = r.run.frames.size() / 2;
  r.truth.features[99] = r.truth.poses[k].head<2>() + Eigen::Vector2d(3.0, 2.0);
  r.run.frames[k].observations.push_back(
      {99, bearing_from_geometry(r.truth.poses[k], r.truth.features[99], kTruth)});
  internal::Built b = internal::build(r.run, options(), r.truth, false);
  Eigen::Matrix3d C;
  double v = 0;
  ASSERT_TRUE(internal::marginal_with_time_offset(&b, &C, &v));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(C(i, j), ref(i, j), 1e-4 * std::sqrt(ref(i, i) * ref(j, j)));
  EXPECT_NEAR(v, ref_v, 1e-4 * ref_v);
}

TEST(TimeOffsetRefinement, WithoutTheOptionNothingIsEstimated) {
  const TimedRun r = make_run(0.04, 2);
  CalibrationOptions o = options();
  o.refinement.estimate_time_offset = false;
  const RefinementResult res = refine_batch(r.run, o, r.truth);
  EXPECT_FALSE(res.time_offset_estimated);
  EXPECT_EQ(res.solution.time_offset, 0.0);
}

}  // namespace
}  // namespace omnivert::calib
