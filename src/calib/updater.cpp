#include "calib/updater.hpp"

#include <Eigen/Cholesky>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

#include "omnivert/calib/model.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

bool joseph_update(const Eigen::MatrixXd& H,
                   const Eigen::MatrixXd& R,
                   Eigen::MatrixXd* P,
                   Eigen::MatrixXd* K_out) {
  const Eigen::MatrixXd PHt = (*P) * H.transpose();
  const Eigen::MatrixXd S = H * PHt + R;
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  if (llt.info() != Eigen::Success) return false;
  // K = P H^T S^-1, i.e. K^T = S^-1 H P (S symmetric): a Cholesky solve, no inverse.
  const Eigen::MatrixXd K = llt.solve(PHt.transpose()).transpose();
  // (I - K H) P (I - K H)^T evaluated by associativity without forming the n x n matrix
  // I - K H: A = (I - K H) P = P - K (H P), then A (I - K H)^T = A - (A H^T) K^T. Every
  // product has the m bearings as a dimension: O(n^2 m) instead of O(n^3). (Measured on the
  // hall, 318 tracks: no change in the filter's time; the update was not its bottleneck.)
  Eigen::MatrixXd A = *P;
  A.noalias() -= K * PHt.transpose();
  const Eigen::MatrixXd AHt = A * H.transpose();
  Eigen::MatrixXd Pn = A;
  Pn.noalias() -= AHt * K.transpose();
  Pn.noalias() += K * R * K.transpose();
  *P = 0.5 * (Pn + Pn.transpose());
  if (K_out) *K_out = K;
  return true;
}

bool joseph_update(const Eigen::SparseMatrix<double>& H,
                   const Eigen::VectorXd& r,
                   Eigen::MatrixXd* P) {
  const Eigen::MatrixXd PHt = (*P) * H.transpose();
  Eigen::MatrixXd S = H * PHt;
  S.diagonal() += r;
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  if (llt.info() != Eigen::Success) return false;
  const Eigen::MatrixXd K = llt.solve(PHt.transpose()).transpose();
  // (I - K H) P (I - K H)^T + K R K^T = A - A H^T K^T + K R K^T with A = (I - K H) P.
  Eigen::MatrixXd A = *P;
  A.noalias() -= K * PHt.transpose();
  Eigen::MatrixXd B = A * H.transpose();
  B.noalias() -= K * r.asDiagonal();
  A.noalias() -= B * K.transpose();
  *P = 0.5 * (A + A.transpose());
  return true;
}

namespace {

using RowSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// h P h^T of row `row` of H over its nonzero entries (eq. 30: the bearing's feature, the
// extrinsics, a bias), a handful instead of dim^2.
double row_variance(const RowSparse& H, int row, const Eigen::MatrixXd& P) {
  double hph = 0.0;
  for (RowSparse::InnerIterator a(H, row); a; ++a)
    for (RowSparse::InnerIterator b(H, row); b; ++b)
      hph += a.value() * P(a.col(), b.col()) * b.value();
  return hph;
}

// Regularised lower incomplete gamma P(a, x): series for x < a + 1, continued fraction
// otherwise (Numerical Recipes, Sec. 6.2).
double gamma_p(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double lg = std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 1000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < 1e-16 * std::abs(sum)) break;
    }
    return sum * std::exp(-x + a * std::log(x) - lg);
  }
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-16) break;
  }
  return 1.0 - std::exp(-x + a * std::log(x) - lg) * h;
}
}  // namespace

double chi2_quantile(double p, int dof) {
  if (p >= 1.0) return std::numeric_limits<double>::infinity();
  if (p <= 0.0 || dof < 1) return 0.0;
  // Bisection on the CDF P(dof / 2, x / 2) (monotone), to 1e-12 relative.
  double lo = 0.0, hi = dof + 20.0 * std::sqrt(2.0 * dof) + 50.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (gamma_p(0.5 * dof, 0.5 * mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Updater::Updater(const CalibrationOptions& options)
    : options_(options), gate_(chi2_quantile(options.association.gate_probability, 1)) {}

Eigen::VectorXd Updater::predict(const FilterState& state,
                                 const Eigen::VectorXd& x,
                                 const std::vector<BearingMeasurement>& z,
                                 Eigen::MatrixXd* H) const {
  const int e = state.extrinsics_index();
  [[maybe_unused]] const bool paper = state.extrinsics_param() == ExtrinsicsParam::kPaper;
  const Extrinsics ex = Extrinsics::from_vec(x.segment<3>(e));  // (phi, rho, psi) if paper
  const Vec3 cam = x.segment<3>(e);                             // (c_x, c_y, eta) otherwise
  const int m = static_cast<int>(z.size());
  Eigen::VectorXd h(m);
  H->setZero(m, state.dim());
  for (int k = 0; k < m; ++k) {
    const FeatureSlot& s = state.slots()[z[k].slot];
    const int i = s.index;
    switch (s.param) {
      case FeatureParam::kDistance:
      case FeatureParam::kInverseDistance: {
        assert(paper);
        Row5 J;
        // Eq. (30), the row of this feature; H of appendix A.4 (chain rule for (q, theta)).
        h(k) = s.param == FeatureParam::kDistance ? predict_bearing(x(i), x(i + 1), ex, &J)
                                                  : predict_bearing_inverse(x(i), x(i + 1), ex, &J);
        (*H)(k, i) = J(0);
        (*H)(k, i + 1) = J(1);
        H->block<1, 3>(k, e) = J.tail<3>();
        break;
      }
      case FeatureParam::kPoint: {
        assert(!paper);
        Eigen::Matrix<double, 1, 2> Jp;
        Row3 Jc;
        h(k) = predict_bearing_point(x.segment<2>(i), cam, &Jp, &Jc);
        H->block<1, 2>(k, i) = Jp;
        H->block<1, 3>(k, e) = Jc;
        break;
      }
      case FeatureParam::kAnchored: {
        assert(!paper);
        Row4 Jf;
        Row3 Jc;
        h(k) = predict_bearing_anchored(x.segment<4>(i), cam, &Jf, &Jc);
        H->block<1, 4>(k, i) = Jf;
        H->block<1, 3>(k, e) = Jc;
        break;
      }
    }
    if (s.bias) {  // CalibrationOptions::noise.track_bias_sigma: eq. (30) + the track's constant
                   // error b
      h(k) += x(s.bias_index());
      (*H)(k, s.bias_index()) = 1.0;
    }
  }
  return h;
}

double Updater::second_order_variance(const FilterState& state, const BearingMeasurement& z) const {
  // Gaussian second-order filter (Bar-Shalom, Li, Kirubarajan 2001, Sec. 10.3): the
  // variance that the curvature of h adds to the prediction, 1/2 tr(Hxx P Hxx P), over the
  // variables the bearing depends on (its feature block and the extrinsics). Large while a
  // depth or the camera pose is poorly known, vanishing as they converge; without it the
  // first updates (small parallax, depth and yaw both uncertain) are overconfident.
  const FeatureSlot& s = state.slots()[z.slot];
  std::vector<int> idx;
  // (Not a track's bias entry, FeatureSlot::bias: h is linear in it, its rows of Hxx are 0.)
  for (int i = 0; i < feature_param_size(s.param); ++i) idx.push_back(s.index + i);
  for (int i = 0; i < 3; ++i) idx.push_back(state.extrinsics_index() + i);
  const int d = static_cast<int>(idx.size());
  const std::vector<BearingMeasurement> one = {z};
  Eigen::MatrixXd Hdummy;
  auto h = [&](const Eigen::VectorXd& x) { return predict(state, x, one, &Hdummy)(0); };
  const double step = 1e-4;
  const Eigen::VectorXd& x0 = state.x();
  Eigen::MatrixXd Hxx(d, d);
  for (int a = 0; a < d; ++a) {
    for (int b = a; b < d; ++b) {
      auto at = [&](double sa, double sb) {
        Eigen::VectorXd x = x0;
        x(idx[a]) += sa * step;
        x(idx[b]) += sb * step;
        return h(x);
      };
      const double h0 = h(x0);
      const double v = angle_diff(at(1, 1), h0) - angle_diff(at(1, -1), h0) -
                       angle_diff(at(-1, 1), h0) + angle_diff(at(-1, -1), h0);
      Hxx(a, b) = Hxx(b, a) = v / (4.0 * step * step);
    }
  }
  Eigen::MatrixXd Pb(d, d);
  for (int a = 0; a < d; ++a)
    for (int b = 0; b < d; ++b) Pb(a, b) = state.P()(idx[a], idx[b]);
  const Eigen::MatrixXd M = Hxx * Pb;
  return 0.5 * (M * M).trace();
}

double Updater::measurement_variance(const FilterState& state, const BearingMeasurement& z) const {
  const double var = options_.noise.bearing_sigma * options_.noise.bearing_sigma;
  return var * z.sigma_scale * z.sigma_scale +
         (options_.filter.second_order_noise ? second_order_variance(state, z) : 0.0);
}

double Updater::innovation_chi2(const FilterState& state,
                                const BearingMeasurement& z,
                                double* prediction_variance) const {
  Eigen::MatrixXd H;
  const Eigen::VectorXd h = predict(state, state.x(), {z}, &H);
  const double var = measurement_variance(state, z);
  const double r = angle_diff(z.beta, h(0));
  // Over H's nonzero entries: O(1), not O(dim^2), for the filter's search among the features
  // (CalibrationOptions::association.join_pieces).
  const RowSparse H_row = H.sparseView();
  const double hph = row_variance(H_row, 0, state.P());
  if (prediction_variance) *prediction_variance = hph;
  return r * r / (hph + var);
}

std::vector<BearingUpdateResult> Updater::update(const std::vector<BearingMeasurement>& z_all,
                                                 FilterState* state) const {
  std::vector<BearingUpdateResult> results(z_all.size());
  if (z_all.empty()) return results;
  const Eigen::VectorXd x0 = state->x();
  const Eigen::MatrixXd P0 = state->P();

  // Chi-square gate of each bearing on its own, at the prior. H has a handful of nonzeros a
  // row (eq. 30: the bearing's feature, the extrinsics, a bias), so H P H^T is taken over them.
  Eigen::MatrixXd H;
  const Eigen::VectorXd h0 = predict(*state, x0, z_all, &H);
  const RowSparse H_rows = H.sparseView();
  std::vector<BearingMeasurement> z;
  std::vector<int> used;
  std::vector<double> r_var;
  for (std::size_t k = 0; k < z_all.size(); ++k) {
    const double rk = measurement_variance(*state, z_all[k]);
    const double r = angle_diff(z_all[k].beta, h0(k));
    const double hph = row_variance(H_rows, static_cast<int>(k), P0);
    results[k].chi2 = r * r / (hph + rk);
    if (results[k].chi2 <= gate_) {  // also rejects NaN
      z.push_back(z_all[k]);
      used.push_back(static_cast<int>(k));
      r_var.push_back(rk);
    }
  }
  if (z.empty()) return results;
  const int m = static_cast<int>(z.size());
  const Eigen::VectorXd R = Eigen::Map<const Eigen::VectorXd>(r_var.data(), m);

  // Iterated EKF: x_{j+1} = x0 + K_j (z - h(x_j) - H_j (x0 - x_j)), K_j from H_j and P0.
  Eigen::VectorXd xj = x0;
  Eigen::SparseMatrix<double> Hs;
  for (int it = 0; it < options_.filter.update_iterations; ++it) {
    const Eigen::VectorXd hj = predict(*state, xj, z, &H);
    Hs = H.sparseView();
    Eigen::VectorXd r(m);
    for (int k = 0; k < m; ++k) r(k) = angle_diff(z[k].beta, hj(k));  // wrapped innovation
    const Eigen::MatrixXd PHt = P0 * Hs.transpose();
    Eigen::MatrixXd S = Hs * PHt;
    S.diagonal() += R;
    const Eigen::LLT<Eigen::MatrixXd> llt(S);
    if (llt.info() != Eigen::Success) return results;
    const Eigen::VectorXd xn = x0 + PHt * llt.solve(r + Hs * (xj - x0));
    const double step = (xn - xj).norm();
    xj = xn;
    if (step < 1e-10) break;
  }
  // Covariance at the last linearisation, through the shared Joseph update.
  predict(*state, xj, z, &H);
  Hs = H.sparseView();
  if (!joseph_update(Hs, R, &state->mutable_P())) return results;
  state->mutable_x() = xj;
  state->normalise();
  for (int k : used) results[k].accepted = true;
  return results;
}

}  // namespace omnivert::calib
