#pragma once
// Helpers shared by the calibration tests on synthetic runs (calib/synthetic_run.hpp).

#include <Eigen/Cholesky>
#include <cmath>

#include "calib/batch_point.hpp"
#include "calib/synthetic_run.hpp"
#include "omnivert/calib/model.hpp"
#include "omnivert/calib/refinement.hpp"
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
inline CalibrationOptions options_for(const SyntheticRunOptions& so) {
  CalibrationOptions o;
  o.robot.wheel_base = so.wheel_base;
  o.robot.odometry_K = so.odometry_K;
  o.noise.bearing_sigma = so.bearing_sigma;
  return o;
}

// The options with the batch refinement on.
inline CalibrationOptions refined(CalibrationOptions o) {
  o.refinement.enabled = true;
  return o;
}

// NEES of (phi, rho, psi) against the truth (angles wrapped).
inline double nees(const Extrinsics& est, const Eigen::Matrix3d& cov, const Extrinsics& truth) {
  const Eigen::Vector3d e(
      wrap_angle(est.phi - truth.phi), est.rho - truth.rho, wrap_angle(est.psi - truth.psi));
  return e.dot(cov.ldlt().solve(e));
}

// NEES of a refinement's answer against the truth.
inline double nees(const RefinementResult& r, const Extrinsics& truth) {
  return nees(r.extrinsics, r.covariance, truth);
}

// From frame `from` on, the track of feature `f` follows a second line `behind` metres further
// along the camera's ray of frame `from` (same noise): at the slip the two bearings coincide,
// afterwards they drift apart as the robot moves, as a door leaf does behind its frame.
// The point `behind` metres behind track's feature along the camera's ray of frame `from`:
// where slip() moves its bearings.
inline Eigen::Vector2d slip_point(const SyntheticRun& run, int track, int from, double behind) {
  const Eigen::Vector2d f = run.features[run.track_feature.at(track)];
  const Eigen::Vector3d& p = run.true_poses[from];
  const double a = p(2) + run.truth.phi;
  const Eigen::Vector2d c(p(0) + run.truth.rho * std::cos(a), p(1) + run.truth.rho * std::sin(a));
  return f + behind * (f - c).normalized();
}

inline SyntheticRun slip(SyntheticRun run, int track, int from, double behind) {
  const Eigen::Vector2d f = run.features[run.track_feature.at(track)];
  const Eigen::Vector2d g = slip_point(run, track, from, behind);
  for (std::size_t k = from; k < run.run.frames.size(); ++k)
    for (BearingObservation& o : run.run.frames[k].observations)
      if (o.track_id == track)
        o.beta += bearing_from_geometry(run.true_poses[k], g, run.truth) -
                  bearing_from_geometry(run.true_poses[k], f, run.truth);
  return run;
}

// The filter tests' models: the run's wheel base and K, the paper's bearing sigma 0.3 degree
// (whatever the run's noise).
inline CalibrationOptions filter_case_options(const SyntheticRunOptions& so) {
  CalibrationOptions o;
  o.robot.wheel_base = so.wheel_base;
  o.robot.odometry_K = so.odometry_K;
  o.noise.bearing_sigma = deg2rad(0.3);
  return o;
}

// The error of (phi, rho, psi) against the truth (angles wrapped).
inline Eigen::Vector3d error(const Extrinsics& est, const Extrinsics& truth) {
  return {angle_diff(est.phi, truth.phi), est.rho - truth.rho, angle_diff(est.psi, truth.psi)};
}

}  // namespace omnivert::calib::test_support
