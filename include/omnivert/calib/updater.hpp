#pragma once
// EKF update of the self-calibration filter with bearings, eq. (30), and the one function
// through which every covariance update goes.

#include <Eigen/Core>

#include "omnivert/calib/filter_state.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

// The shared covariance update (Joseph form, which keeps P symmetric positive definite for
// any gain): with S = H P H^T + R factored by Cholesky, K = P H^T S^-1,
//   P <- (I - K H) P (I - K H)^T + K R K^T.
// Writes the gain to *K when asked. Returns false (P untouched) if S is not positive definite.
bool joseph_update(const Eigen::MatrixXd& H, const Eigen::MatrixXd& R, Eigen::MatrixXd* P,
                   Eigen::MatrixXd* K = nullptr);

// Quantile of the chi-square distribution (exact for 1 and 2 degrees of freedom,
// Wilson-Hilferty otherwise; relative error < 1e-3 for dof >= 3 at the usual levels).
double chi2_quantile(double p, int dof);

struct BearingUpdateResult {
  bool accepted = false;
  double chi2 = 0.0;  // normalised innovation squared at the prior estimate
};

class Updater {
 public:
  explicit Updater(const Options& options);
  // Updates the state with bearing beta of the feature in `slot`. The innovation is wrapped;
  // a bearing whose normalised innovation exceeds the chi-square gate is rejected. With
  // update_iterations > 1 this is the iterated EKF (Gauss-Newton on the same prior).
  BearingUpdateResult update_bearing(int slot, double beta, FilterState* state) const;

 private:
  // Predicted bearing and its Jacobian row (1 x dim) at state x.
  double predict(const FilterState& state, const Eigen::VectorXd& x, int slot,
                 Eigen::RowVectorXd* H) const;
  Options options_;
  double gate_;
};

}  // namespace omnivert::calib
