// The Lanczos iteration for M^-1/2 b (calib/lanczos.hpp) against the eigen-decomposition.
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "calib/lanczos.hpp"

namespace omnivert::calib::internal {
namespace {

// M = I - H with H = X (X^T X)^-1 X^T + a few smaller leverages: eigenvalues in (0, 1], two of
// them zero (the projection's), as a track's I - H_cc; b without a component along those two.
TEST(Lanczos, InverseSqrtEqualsTheDecomposition) {
  std::mt19937 rng(4);
  std::normal_distribution<double> g;
  const int n = 150;
  Eigen::MatrixXd X(n, 2), Z(n, 30);
  for (int i = 0; i < n; ++i) {
    X.row(i) << g(rng), g(rng);
    for (int k = 0; k < 30; ++k) Z(i, k) = g(rng);
  }
  const Eigen::MatrixXd P = X * (X.transpose() * X).inverse() * X.transpose();
  const Eigen::MatrixXd Zp = (Eigen::MatrixXd::Identity(n, n) - P) * Z;
  const Eigen::MatrixXd M = Eigen::MatrixXd::Identity(n, n) - P -
                            0.9 * Zp * (Zp.transpose() * Zp).inverse() * Zp.transpose();
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b(i) = g(rng);
  b -= P * b;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(M);
  Eigen::VectorXd f(n);
  for (int i = 0; i < n; ++i)
    f(i) = es.eigenvalues()(i) > 1e-6 ? 1.0 / std::sqrt(es.eigenvalues()(i)) : 0.0;
  const Eigen::VectorXd want =
      es.eigenvectors() * f.asDiagonal() * es.eigenvectors().transpose() * b;
  int products = 0;
  const LanczosResult got = lanczos_inverse_sqrt(
      [&](const Eigen::VectorXd& v) {
        ++products;
        return Eigen::VectorXd(M * v);
      },
      b,
      1e-6,
      1e-12,
      200);
  EXPECT_TRUE(got.converged);
  EXPECT_EQ(got.iterations, products);
  EXPECT_LT((got.x - want).norm(), 1e-9 * want.norm());
  // M has three distinct eigenvalues on b's part (1, 0.1 and 0 outside it): a Krylov space
  // of dimension 2 holds the answer, and the iteration stops there.
  EXPECT_LE(got.iterations, 4);
}

TEST(Lanczos, ZeroVectorIsZero) {
  const LanczosResult got = lanczos_inverse_sqrt(
      [](const Eigen::VectorXd& v) { return v; }, Eigen::VectorXd::Zero(5), 1e-6, 1e-10, 10);
  EXPECT_TRUE(got.converged);
  EXPECT_EQ(got.x.norm(), 0.0);
}

}  // namespace
}  // namespace omnivert::calib::internal
