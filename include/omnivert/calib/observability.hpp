#pragma once
// Observability of the extrinsics and their Cramer-Rao bounds for a recorded trajectory
// (Sec. 8.1), on the batch formulation of batch_point.hpp.

#include <string>

#include <Eigen/Core>

#include "omnivert/calib/batch_point.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

// Verdict on one parameter (or combination) of the extrinsics.
struct ParameterVerdict {
  bool determined = false;
  double crlb = 0.0;  // Cramer-Rao standard deviation (infinity when not determined)
};

struct ObservabilityOptions {
  double max_sigma_angle = 0.035;           // [rad] (2 degrees) an angle with a larger bound is
                                            // reported as not determined
  double max_sigma_rho = 0.02;              // [m]
  double relative_eigenvalue_floor = 1e-9;  // eigenvalues below floor * max count as zero
  // phi, rho and psi individually need the robot to turn (Sec. 8.1). A run whose heading
  // spans less than this many sigmas of its own odometry noise did not turn: the bounds at
  // its estimated trajectory come from heading noise (a straight run at 0.025 degree of
  // bearing noise: rho's bound 15.6 mm, under the 2 cm above), and they are not determined.
  double min_rotation_sigmas = 5.0;
  // (numerical null directions reach 2e-12)
};

// Sec. 8.1 for a recorded trajectory, from the Fisher information J^T Sigma^-1 J of the batch
// problem at `at`, marginalised onto (phi, rho, psi) (Schur complement).
struct ObservabilityReport {
  ParameterVerdict phi, rho, psi;
  ParameterVerdict yaw;                                   // phi + psi
  ParameterVerdict x, y;                                  // camera position rho (cos phi, sin phi)
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();  // marginal Fisher information
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();  // of the information scaled by
                                                          // the thresholds (dimensionless)
  double heading_range = 0.0;  // [rad] max - min of the robot's heading along the run
  double heading_noise = 0.0;  // [rad] sigma of the heading odometry alone accumulates (eq. 31)
  int rank = 0;                // numerical rank of the marginal information
  double condition = 0.0;      // its condition number (scaled), infinity when singular
  Eigen::Matrix3d crlb_covariance = Eigen::Matrix3d::Zero();  // inverse information
  bool all_determined() const { return phi.determined && rho.determined && psi.determined; }
  std::string message;  // what is (not) determined and the motion that would fix it
};

ObservabilityReport analyse_observability(const CalibrationRun& run,
                                          const Options& options,
                                          const BatchPoint& at,
                                          const BatchOptions& batch = {},
                                          const ObservabilityOptions& obs = {});

}  // namespace omnivert::calib
