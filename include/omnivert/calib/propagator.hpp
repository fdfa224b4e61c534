#pragma once
// EKF prediction of the self-calibration filter: dynamics eq. (29), Jacobians F_x, F_u of
// appendix A.4 and the Chong-Kleeman odometry noise of eq. (31):
//   X' = f(X, u),  P' = F_x P F_x^T + F_u Q F_u^T,  Q = diag(K' |d_R|, K' |d_L|),
// with K' = K * inflation (the paper inflates K five-fold).

#include "omnivert/calib/filter_state.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

class Propagator {
 public:
  explicit Propagator(const Options& options) : options_(options) {}
  // One odometry step of wheel travels (d_right, d_left) [m].
  void propagate(double d_right, double d_left, FilterState* state) const;

 private:
  Options options_;
};

}  // namespace omnivert::calib
