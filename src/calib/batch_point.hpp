#pragma once
// The batch (whole-run) formulation of the calibration problem, shared by the maximum
// likelihood refinement (Ceres) and the observability / Cramer-Rao analysis:
//   unknowns: robot poses (x, y, theta) of frames 1..N (frame 0 is the origin: the gauge),
//             features as world points (x_f, y_f), extrinsics (phi, rho, psi);
//   factors:  odometry between consecutive frames, eq. (14)-(15), with the Chong-Kleeman
//             covariance of the wheel travels, eq. (31); a bearing per observation,
//             beta = atan2(y_f - y_C, x_f - x_C) - (theta_R + phi + psi) (eq. 16-17).
// The odometry factor has three residuals: the two wheel travels implied by the pose change
// (eq. 14-15 inverted) against the encoders, and the lateral slip, which a differential drive
// cannot do (sigma `lateral_sigma`).

#include <vector>

#include <Eigen/Core>

#include "omnivert/calib/calibration_filter.hpp"
#include "omnivert/calib/options.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

// Dead-reckoned poses, eq. (14), from the encoder increments.
std::vector<Eigen::Vector3d> dead_reckoning(const CalibrationRun& run, double wheel_base);

// A starting point from a filter run: dead-reckoned poses, each track's last filter estimate
// (D, theta) placed in the world from its frame's pose, the filter's extrinsics.
BatchPoint batch_point_from_filter(const CalibrationRun& run,
                                   const CalibrationOptions& options,
                                   const FilterResult& filter);

}  // namespace omnivert::calib
