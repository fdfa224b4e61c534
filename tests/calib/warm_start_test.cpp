// The refinement's warm start over a long run (warm_start.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include <Eigen/Dense>

#include "calib/batch_point.hpp"
#include "calib/synthetic_run.hpp"
#include "calib/warm_start.hpp"
#include "omnivert/calib/refinement.hpp"
#include "omnivert/core/angles.hpp"
#include "synthetic_support.hpp"

namespace omnivert::calib {
namespace {

using test_support::options_for;
using test_support::truth_point;

// Where a filter run would start the batch: dead-reckoned poses, each feature placed in the
// world from the dead-reckoned pose of its last frame (batch_point_from_filter).
BatchPoint filter_like_start(const SyntheticRun& run, double wheel_base) {
  BatchPoint p;
  p.poses = dead_reckoning(run.run, wheel_base);
  p.extrinsics = run.truth;
  std::map<int, int> last;
  for (std::size_t k = 0; k < run.run.frames.size(); ++k)
    for (const BearingObservation& o : run.run.frames[k].observations)
      last[o.track_id] = static_cast<int>(k);
  for (const auto& [id, k] : last) {
    const Eigen::Vector3d& t = run.true_poses[static_cast<std::size_t>(k)];
    const Eigen::Vector3d& d = p.poses[static_cast<std::size_t>(k)];
    const Eigen::Vector2d robot =
        Eigen::Rotation2Dd(-t(2)) *
        (run.features[static_cast<std::size_t>(run.track_feature.at(id))] - t.head<2>());
    p.features[id] = Eigen::Rotation2Dd(d(2)) * robot + d.head<2>();
  }
  return p;
}

double largest_heading_error(const std::vector<Eigen::Vector3d>& poses,
                             const std::vector<Eigen::Vector3d>& truth) {
  double worst = 0.0;
  for (std::size_t k = 0; k < poses.size(); ++k)
    worst = std::max(worst, std::abs(wrap_angle(poses[k](2) - truth[k](2))));
  return worst;
}

// A long zigzag whose wheels drift: the warm start takes the drift out of the poses, and the
// refinement from the dead-reckoned start ends where it ends from the truth.
TEST(WarmStart, TakesTheDriftOutAndTheRefinementEndsWhereItEndsFromTheTruth) {
  SyntheticRunOptions so;
  so.trajectory = Trajectory::kZigzag;
  so.zigzag_legs = 4;
  so.straight_length = 12.0;
  so.num_features = 20;
  so.break_probability = 0.02;
  so.odometry_K = 2e-4;
  so.bearing_sigma = deg2rad(0.05);
  so.seed = 5;
  const SyntheticRun run = make_synthetic_run(so);
  CalibrationOptions o = options_for(so);
  o.refinement.warm_start_window = 100;
  ASSERT_GE(run.run.frames.size(), 2u * static_cast<std::size_t>(o.refinement.warm_start_window));
  const BatchPoint start = filter_like_start(run, so.wheel_base);
  const BatchPoint warm = internal::warm_start(run.run, o, start);
  const double drift = largest_heading_error(start.poses, run.true_poses);
  const double left = largest_heading_error(warm.poses, run.true_poses);
  EXPECT_GT(drift, deg2rad(1.0));  // the wheels alone drift
  EXPECT_LT(left, 0.25 * drift) << "dead reckoning " << rad2deg(drift) << " deg, warm start "
                                << rad2deg(left) << " deg";
  std::printf("dead reckoning %.2f deg, warm start %.2f deg\n", rad2deg(drift), rad2deg(left));
  EXPECT_EQ(warm.extrinsics.phi, start.extrinsics.phi);  // held
  EXPECT_EQ(warm.features.size(), start.features.size());

  const RefinementResult from_start = refine_batch(run.run, o, start);
  CalibrationOptions cold = o;
  cold.refinement.warm_start_window = 0;
  const RefinementResult from_truth = refine_batch(run.run, cold, truth_point(run));
  EXPECT_NEAR(wrap_angle(from_start.extrinsics.phi - from_truth.extrinsics.phi), 0.0, 1e-6);
  EXPECT_NEAR(from_start.extrinsics.rho - from_truth.extrinsics.rho, 0.0, 1e-6);
  EXPECT_NEAR(wrap_angle(from_start.extrinsics.psi - from_truth.extrinsics.psi), 0.0, 1e-6);

  // Off, or shorter than two windows: the start as it is.
  const BatchPoint same = internal::warm_start(run.run, cold, start);
  EXPECT_EQ(same.poses, start.poses);
  CalibrationOptions wide = o;
  wide.refinement.warm_start_window = static_cast<int>(run.run.frames.size());
  EXPECT_EQ(internal::warm_start(run.run, wide, start).poses, start.poses);
}

TEST(WarmStart, BadWindowsAreRefused) {
  CalibrationOptions o;
  std::string why;
  o.refinement.warm_start_window = -1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("warm_start_window"), std::string::npos) << why;
  o.refinement.warm_start_window = 100;
  o.refinement.warm_start_overlap = 100;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("warm_start_overlap"), std::string::npos) << why;
  o.refinement.warm_start_overlap = 20;
  EXPECT_TRUE(o.IsValid(&why)) << why;
}

}  // namespace
}  // namespace omnivert::calib
