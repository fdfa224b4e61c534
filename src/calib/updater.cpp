#include "omnivert/calib/updater.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "omnivert/calib/model.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

bool joseph_update(const Eigen::MatrixXd& H, const Eigen::MatrixXd& R, Eigen::MatrixXd* P,
                   Eigen::MatrixXd* K_out) {
  const Eigen::MatrixXd PHt = (*P) * H.transpose();
  const Eigen::MatrixXd S = H * PHt + R;
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  if (llt.info() != Eigen::Success) return false;
  // K = P H^T S^-1, i.e. K^T = S^-1 H P (S symmetric): a Cholesky solve, no inverse.
  const Eigen::MatrixXd K = llt.solve(PHt.transpose()).transpose();
  Eigen::MatrixXd IKH = -K * H;
  IKH.diagonal().array() += 1.0;
  Eigen::MatrixXd Pn = IKH * (*P) * IKH.transpose() + K * R * K.transpose();
  *P = 0.5 * (Pn + Pn.transpose());
  if (K_out) *K_out = K;
  return true;
}

namespace {
// Inverse of the standard normal CDF by bisection on erfc (called rarely).
double normal_quantile(double p) {
  double lo = -40.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double cdf = 0.5 * std::erfc(-mid / std::sqrt(2.0));
    (cdf < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}
}  // namespace

double chi2_quantile(double p, int dof) {
  if (p >= 1.0) return std::numeric_limits<double>::infinity();
  if (p <= 0.0) return 0.0;
  if (dof == 1) {
    const double z = normal_quantile(0.5 * (1.0 + p));
    return z * z;
  }
  if (dof == 2) return -2.0 * std::log1p(-p);
  const double k = dof;
  const double z = normal_quantile(p);
  const double a = 2.0 / (9.0 * k);
  const double t = 1.0 - a + z * std::sqrt(a);
  return k * t * t * t;
}

Updater::Updater(const Options& options)
    : options_(options), gate_(chi2_quantile(options.gate_probability, 1)) {}

double Updater::predict(const FilterState& state, const Eigen::VectorXd& x, int slot,
                        Eigen::RowVectorXd* H) const {
  const int i = FilterState::feature_index(slot);
  const int e = state.extrinsics_index();
  const Extrinsics ex = Extrinsics::from_vec(x.segment<3>(e));
  Row5 J;
  // Eq. (30), the row of feature `slot`; H of appendix A.4 (chain rule for (q, theta)).
  const double beta = state.slots()[slot].param == FeatureParam::kDistance
                          ? predict_bearing(x(i), x(i + 1), ex, &J)
                          : predict_bearing_inverse(x(i), x(i + 1), ex, &J);
  H->setZero(state.dim());
  (*H)(i) = J(0);
  (*H)(i + 1) = J(1);
  H->segment<3>(e) = J.tail<3>();
  return beta;
}

BearingUpdateResult Updater::update_bearing(int slot, double beta, FilterState* state) const {
  BearingUpdateResult result;
  const double R = options_.bearing_sigma * options_.bearing_sigma;
  const Eigen::VectorXd x0 = state->x();
  const Eigen::MatrixXd& P0 = state->P();
  Eigen::RowVectorXd H;
  const double h0 = predict(*state, x0, slot, &H);
  const double r0 = angle_diff(beta, h0);  // wrapped innovation
  const double S0 = (H * P0 * H.transpose())(0, 0) + R;
  result.chi2 = r0 * r0 / S0;
  if (!(result.chi2 <= gate_)) return result;  // chi-square gate (also rejects NaN)

  // Iterated EKF: x_{j+1} = x0 + K_j (z - h(x_j) - H_j (x0 - x_j)), K_j from H_j and P0.
  Eigen::VectorXd xj = x0;
  double r = r0;
  Eigen::VectorXd xn = x0;
  for (int it = 0; it < options_.update_iterations; ++it) {
    if (it > 0) {
      const double hj = predict(*state, xj, slot, &H);
      r = angle_diff(beta, hj);
    }
    const Eigen::VectorXd PHt = P0 * H.transpose();
    const double S = H.dot(PHt) + R;
    const Eigen::VectorXd K = PHt / S;
    xn = x0 + K * (r + H.dot(xj - x0));
    if ((xn - xj).norm() < 1e-10) {
      xj = xn;
      break;
    }
    xj = xn;
  }
  // Covariance with the last linearisation, through the shared Joseph update.
  if (options_.update_iterations > 1) {
    predict(*state, xj, slot, &H);
  }
  Eigen::MatrixXd Hm = H;
  Eigen::MatrixXd Rm(1, 1);
  Rm(0, 0) = R;
  if (!joseph_update(Hm, Rm, &state->mutable_P())) return result;
  state->mutable_x() = xj;
  state->normalise();
  result.accepted = true;
  return result;
}

}  // namespace omnivert::calib
