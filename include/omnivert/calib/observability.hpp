#pragma once
// Observability of the extrinsics and their Cramer-Rao bounds for a recorded trajectory
// (Sec. 8.1), on the batch formulation of batch_point.hpp.

#include <string>

#include <Eigen/Core>

#include "omnivert/calib/options.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

// Verdict on one parameter (or combination) of the extrinsics.
struct ParameterVerdict {
  bool determined = false;
  double crlb = 0.0;  // Cramer-Rao standard deviation (infinity when not determined)
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
                                          const CalibrationOptions& options,
                                          const BatchPoint& at);

}  // namespace omnivert::calib
