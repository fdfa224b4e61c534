// The batch refinement's answer (refinement.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include <Eigen/Dense>

#include "calib/synthetic_run.hpp"
#include "omnivert/calib/batch_point.hpp"
#include "omnivert/calib/refinement.hpp"
#include "omnivert/core/angles.hpp"
#include "synthetic_support.hpp"

namespace omnivert::calib {
namespace {

using test_support::nees;
using test_support::options_for;
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

}  // namespace
}  // namespace omnivert::calib
