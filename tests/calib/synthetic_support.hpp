#pragma once
// Helpers shared by the calibration tests on synthetic runs (calib/synthetic_run.hpp).

#include <Eigen/Cholesky>

#include "omnivert/calib/batch_point.hpp"
#include "omnivert/calib/synthetic_run.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib::test_support {

// The batch problem at the truth: true poses, features and extrinsics.
inline BatchPoint truth_point(const SyntheticRun& run) {
  BatchPoint p;
  p.poses = run.true_poses;
  p.extrinsics = run.truth;
  for (const auto& [id, j] : run.track_feature) p.features[id] = run.features[j];
  return p;
}

// Models matching the run: its wheel base, K and bearing noise.
inline Options options_for(const SyntheticRunOptions& so) {
  Options o;
  o.wheel_base = so.wheel_base;
  o.odometry_K = so.odometry_K;
  o.bearing_sigma = so.bearing_sigma;
  return o;
}

// NEES of (phi, rho, psi) against the truth (angles wrapped).
inline double nees(const Extrinsics& est, const Eigen::Matrix3d& cov, const Extrinsics& truth) {
  const Eigen::Vector3d e(wrap_angle(est.phi - truth.phi), est.rho - truth.rho,
                          wrap_angle(est.psi - truth.psi));
  return e.dot(cov.ldlt().solve(e));
}

}  // namespace omnivert::calib::test_support
