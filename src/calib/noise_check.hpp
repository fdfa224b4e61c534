#pragma once
// The checks of diagnostics.hpp on a solved batch problem.

#include "calib/batch_point.hpp"
#include "calib/batch_problem.hpp"
#include "omnivert/calib/diagnostics.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib::internal {

// BatchNoiseCheck::wheels (WheelCheck): per frame, the wheels' rotation minus the solution's,
// with the variance eq. (31) gives the wheels' (K x batch inflation, composed over the frame's
// samples), fitted by weighted least squares as s x (the solution's rotation) + c x (distance
// rolled).
WheelCheck wheel_check(const Built& b,
                       const CalibrationRun& run,
                       const CalibrationOptions& options);

// The error of the extrinsics measured by the data themselves (BatchNoiseCheck): at the
// solution theta^ of the whitened problem (residuals r, Jacobian J, Fisher information
// F = J^T J), the estimate's first-order error is -F^-1 J^T e for the true errors e. The
// extrinsics' rows of F^-1 are A (3 x n); the model covariance is A F A^T = [F^-1]_ee, which
// holds when every whitened error is independent with unit variance. The bearings of one
// track are not independent (an edge's position error changes slowly from frame to frame,
// and two nearly aligned lines pull a track's detections together), so the errors are
// summed per track before they are squared: the cluster-robust ("sandwich") covariance
// sum_c (A J_c^T r_c)(A J_c^T r_c)^T over clusters c (each track's bearings; each odometry
// factor). A track's own feature point absorbs the part of its errors along its own columns
// of J, and that part does not reach the extrinsics (A F_{:,f} = 0), so the fitted residuals
// stand in for the true errors up to the leverage of the shared variables.
// options: dense_limit and dense_track_limit (NoiseCheckOptions).
BatchNoiseCheck noise_check(Built& b, const NoiseCheckOptions& options);

}  // namespace omnivert::calib::internal
