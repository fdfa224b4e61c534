#pragma once
// EKF prediction of the self-calibration filter: dynamics eq. (29), Jacobians F_x, F_u of
// appendix A.4 and the Chong-Kleeman odometry noise of eq. (31):
//   X' = f(X, u),  P' = F_x P F_x^T + F_u Q F_u^T,  Q = diag(K' |d_R|, K' |d_L|),
// with K' = K * inflation (the paper inflates K five-fold; our default is 1: types.hpp).

#include <array>
#include <vector>

#include <Eigen/Core>

#include "calib/filter_state.hpp"
#include "omnivert/calib/options.hpp"

namespace omnivert::calib {

class Propagator {
 public:
  explicit Propagator(const CalibrationOptions& options) : options_(options) {}
  // One odometry step of wheel travels (d_right, d_left) [m].
  void propagate(double d_right, double d_left, FilterState* state) const;
  // One frame's motion (FrameInput: wheel travels and sideways displacement). With a
  // sideways displacement beyond three sigmas of its noise the motion is made of two steps
  // of eq. (29), a turn in place and a step of eq. (14), that compose to it exactly
  // (frame_steps); otherwise one step.
  void propagate(const FrameInput& frame, FilterState* state) const;

 private:
  CalibrationOptions options_;
};

// One diagonal block of F_x other than the identity: rows and columns index..index+A.rows()-1.
struct TransitionBlock {
  int index = 0;
  Eigen::MatrixXd A;
};

// P <- F P F^T + G Q G^T, F the identity but for the blocks (appendix A.4: A^i per feature, the
// extrinsics and biases unchanged), which do not overlap: each block multiplies its rows, then
// its columns, O(n^2) per feature dimension instead of the dense O(n^3)
// (Propagator.BlockCovarianceEqualsTheDenseProduct against F P F^T formed densely).
void propagate_covariance(const std::vector<TransitionBlock>& F,
                          const Eigen::MatrixXd& G,
                          const Eigen::Matrix2d& Q,
                          Eigen::MatrixXd* P);

// The two steps of eq. (14), (d_right, d_left) each, that compose to one step with the
// sideways displacement `lateral` (FrameInput::lateral): a turn in place by alpha, then a
// step whose mid-step heading points along the displacement. When lateral is 0, or the
// displacement too short to give it a direction, the first is the step itself and the
// second zero.
std::array<Eigen::Vector2d, 2> frame_steps(double d_right,
                                           double d_left,
                                           double lateral,
                                           double wheel_base);

}  // namespace omnivert::calib
