#pragma once
// EKF update of the self-calibration filter with bearings, eq. (30), and the one function
// through which every covariance update goes.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "calib/filter_state.hpp"
#include "omnivert/calib/options.hpp"

namespace omnivert::calib {

// The shared covariance update (Joseph form, which keeps P symmetric positive definite for
// any gain): with S = H P H^T + R factored by Cholesky, K = P H^T S^-1,
//   P <- (I - K H) P (I - K H)^T + K R K^T.
// Writes the gain to *K when asked. Returns false (P untouched) if S is not positive definite.
bool joseph_update(const Eigen::MatrixXd& H,
                   const Eigen::MatrixXd& R,
                   Eigen::MatrixXd* P,
                   Eigen::MatrixXd* K = nullptr);

// The same update for a sparse H (each bearing's row touches its feature, the extrinsics and
// a bias: eq. 30) and a diagonal R = diag(r), the filter's case: the products with H cost
// n x nnz(H) instead of n^2 x m, and the Joseph form's two n^2 x m products remain,
//   A = P - K (P H^T)^T,   P <- A - (A H^T - K R) K^T.
// joseph_update is its plain reference (Updater.SparseJosephUpdateEqualsTheDenseOne).
bool joseph_update(const Eigen::SparseMatrix<double>& H,
                   const Eigen::VectorXd& r,
                   Eigen::MatrixXd* P);

// Quantile of the chi-square distribution with dof degrees of freedom (bisection on the
// regularised incomplete gamma function; accurate to ~1e-10).
double chi2_quantile(double p, int dof);

struct BearingMeasurement {
  int slot = -1;             // feature slot in the state
  double beta = 0.0;         // measured bearing [rad]
  double sigma_scale = 1.0;  // its sigma is CalibrationOptions::noise.bearing_sigma x this
};

struct BearingUpdateResult {
  bool accepted = false;
  double chi2 = 0.0;  // normalised innovation squared at the prior estimate
};

class Updater {
 public:
  explicit Updater(const CalibrationOptions& options);
  // Updates the state with all bearings of one frame at once (eq. 30: one stacked h, one
  // linearisation point for the frame, so that sequential scalar updates cannot gain
  // information along directions the frame does not observe). Innovations are wrapped; a
  // bearing whose normalised innovation (on its own) exceeds the chi-square gate is rejected
  // and the others are used. With update_iterations > 1 this is the iterated EKF
  // (Gauss-Newton on the same prior). Returns one result per measurement.
  std::vector<BearingUpdateResult> update(const std::vector<BearingMeasurement>& z,
                                          FilterState* state) const;
  // The gate's statistic of one bearing against the state's prediction, without updating:
  // the normalised innovation squared r^2 / (H P H^T + R) (R with the second-order term).
  // *prediction_variance (when given): the predicted bearing's variance, H P H^T.
  double innovation_chi2(const FilterState& state,
                         const BearingMeasurement& z,
                         double* prediction_variance = nullptr) const;
  // The chi-square gate (CalibrationOptions::association.gate_probability, 1 degree of freedom).
  double gate() const { return gate_; }

 private:
  // Predicted bearings and Jacobian (m x dim) at state x.
  Eigen::VectorXd predict(const FilterState& state,
                          const Eigen::VectorXd& x,
                          const std::vector<BearingMeasurement>& z,
                          Eigen::MatrixXd* H) const;
  // R of one bearing: bearing_sigma^2 x sigma_scale^2, plus the second-order term when on.
  double measurement_variance(const FilterState& state, const BearingMeasurement& z) const;
  // Variance added by the curvature of h (second-order filter), see the source.
  double second_order_variance(const FilterState& state, const BearingMeasurement& z) const;
  CalibrationOptions options_;
  double gate_;
};

}  // namespace omnivert::calib
