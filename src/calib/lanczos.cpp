#include "calib/lanczos.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>

namespace omnivert::calib::internal {

LanczosResult lanczos_inverse_sqrt(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& apply,
    const Eigen::VectorXd& b,
    double floor,
    double tolerance,
    int max_iterations) {
  LanczosResult out;
  const Eigen::Index n = b.size();
  out.x = Eigen::VectorXd::Zero(n);
  const double beta0 = b.norm();
  if (!(beta0 > 0.0)) {
    out.converged = true;
    return out;
  }
  const int k_max = static_cast<int>(std::min<Eigen::Index>(max_iterations, n));
  Eigen::MatrixXd Q(n, k_max);
  Q.col(0) = b / beta0;
  std::vector<double> alpha, beta;
  for (int j = 0; j < k_max; ++j) {
    Eigen::VectorXd w = apply(Q.col(j));
    const double a = Q.col(j).dot(w);
    w -= a * Q.col(j);
    if (j > 0) w -= beta[j - 1] * Q.col(j - 1);
    // Full re-orthogonalisation, twice ("twice is enough"): without it the basis loses
    // orthogonality as Ritz values converge and f(T_k) e_1 is no longer f(M) b.
    for (int pass = 0; pass < 2; ++pass)
      w -= Q.leftCols(j + 1) * (Q.leftCols(j + 1).transpose() * w);
    alpha.push_back(a);
    const double b_next = w.norm();
    // x_j = ||b|| Q_j f(T_j) e_1, T_j the tridiagonal (alpha, beta) of order j + 1.
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es;
    es.computeFromTridiagonal(Eigen::Map<const Eigen::VectorXd>(alpha.data(), j + 1),
                              Eigen::Map<const Eigen::VectorXd>(beta.data(), j));
    Eigen::VectorXd f(j + 1);
    for (int i = 0; i <= j; ++i) {
      const double theta = es.eigenvalues()(i);
      f(i) = theta > floor ? 1.0 / std::sqrt(theta) : 0.0;
    }
    const Eigen::VectorXd y =
        beta0 * (es.eigenvectors() * f.asDiagonal() * es.eigenvectors().row(0).transpose());
    const Eigen::VectorXd x = Q.leftCols(j + 1) * y;
    const double change = (x - out.x).norm();
    out.x = x;
    out.iterations = j + 1;
    // The Krylov space is invariant (b_next ~ 0): x is exact. Or the last iteration changed
    // it by less than the tolerance.
    if (b_next <= 1e-13 * std::abs(alpha[0]) || (j > 0 && change <= tolerance * x.norm())) {
      out.converged = true;
      return out;
    }
    if (j + 1 < k_max) {
      beta.push_back(b_next);
      Q.col(j + 1) = w / b_next;
    }
  }
  return out;
}

}  // namespace omnivert::calib::internal
