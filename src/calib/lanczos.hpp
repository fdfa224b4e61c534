#pragma once
// f(M) b for a symmetric positive semi-definite M known only through products M v, by the
// Lanczos iteration (Golub and Van Loan, Matrix Computations, 4th ed., Sec. 10.1; the
// approximation ||b|| Q_k f(T_k) e_1 of Higham, Functions of Matrices, Sec. 13.2). Used for
// M^-1/2 b where M is too large to decompose: the noise check's long tracks
// (noise_check.cpp).

#include <functional>

#include <Eigen/Core>

namespace omnivert::calib::internal {

struct LanczosResult {
  Eigen::VectorXd x;
  int iterations = 0;
  bool converged = false;
};

// M^-1/2 b on the eigenvalues of M above `floor` (those at or below it count as zero, as in
// the pseudo-inverse), to `tolerance` relative change between iterations; at most
// `max_iterations` products. Full re-orthogonalisation: the basis is n x iterations.
LanczosResult lanczos_inverse_sqrt(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& apply,
    const Eigen::VectorXd& b,
    double floor,
    double tolerance,
    int max_iterations);

}  // namespace omnivert::calib::internal
