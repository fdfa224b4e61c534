// The forward substitution over the elimination-tree paths (calib/factor_paths.hpp) against
// the dense inverse of the same matrix.
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include "calib/factor_paths.hpp"

namespace omnivert::calib::internal {
namespace {

// A run-like information matrix: a chain of 3-variable poses (odometry), features of 2
// variables each seen from a stretch of poses, 3 shared variables seen by every feature.
Eigen::SparseMatrix<double> run_like_information(int poses, int features, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> start(0, poses - 1), span(1, 40);
  const int n = 3 * poses + 2 * features + 3;
  std::vector<Eigen::Triplet<double>> rows;  // J as triplets (row, column, value)
  int row = 0;
  for (int k = 0; k + 1 < poses; ++k, ++row)
    for (int v = 0; v < 6; ++v) rows.emplace_back(row, 3 * k + v, u(rng));
  for (int f = 0; f < features; ++f) {
    const int a = start(rng), b = std::min(poses - 1, a + span(rng));
    for (int k = a; k <= b; ++k, ++row) {
      for (int v = 0; v < 3; ++v) rows.emplace_back(row, 3 * k + v, u(rng));
      for (int v = 0; v < 2; ++v) rows.emplace_back(row, 3 * poses + 2 * f + v, u(rng));
      for (int v = 0; v < 3; ++v) rows.emplace_back(row, n - 3 + v, u(rng));
    }
  }
  Eigen::SparseMatrix<double> J(row, n);
  J.setFromTriplets(rows.begin(), rows.end());
  Eigen::SparseMatrix<double> F = J.transpose() * J;
  for (int i = 0; i < n; ++i) F.coeffRef(i, i) += 1e-3;
  return F;
}

TEST(FactorPaths, BlocksEqualTheDenseInverse) {
  const Eigen::SparseMatrix<double> F = run_like_information(300, 120, 5);
  FactorPaths::Factor factor(F);
  ASSERT_EQ(factor.info(), Eigen::Success);
  const Eigen::MatrixXd Finv = Eigen::LDLT<Eigen::MatrixXd>(Eigen::MatrixXd(F))
                                   .solve(Eigen::MatrixXd::Identity(F.rows(), F.cols()));
  FactorPaths paths(factor);
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> variable(0, static_cast<int>(F.rows()) - 1), count(1, 6);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int short_paths = 0;
  for (int trial = 0; trial < 40; ++trial) {
    // Two random sparse blocks B and C: B^T F^-1 C from the paths and from the dense inverse.
    std::vector<std::vector<std::pair<int, double>>> B(count(rng)), C(count(rng));
    Eigen::MatrixXd Bd = Eigen::MatrixXd::Zero(F.rows(), B.size());
    Eigen::MatrixXd Cd = Eigen::MatrixXd::Zero(F.rows(), C.size());
    for (std::size_t k = 0; k < B.size(); ++k)
      for (int e = 0; e < 3; ++e) {
        const int v = variable(rng);
        const double x = u(rng);
        B[k].emplace_back(v, x);
        Bd(v, static_cast<Eigen::Index>(k)) += x;
      }
    for (std::size_t k = 0; k < C.size(); ++k) {
      const int v = variable(rng);
      C[k].emplace_back(v, 1.0);
      Cd(v, static_cast<Eigen::Index>(k)) = 1.0;
    }
    const FactorPaths::Forward yb = paths.solve(B), yc = paths.solve(C);
    if (2 * static_cast<Eigen::Index>(yc.rows.size()) < F.rows()) ++short_paths;
    const Eigen::MatrixXd want_bc = Bd.transpose() * Finv * Cd;
    const Eigen::MatrixXd want_bb = Bd.transpose() * Finv * Bd;
    const Eigen::MatrixXd got_bc = paths.gram(yb, yc), got_bb = paths.gram(yb, yb);
    ASSERT_EQ(got_bc.rows(), want_bc.rows());
    ASSERT_EQ(got_bc.cols(), want_bc.cols());
    EXPECT_LT((got_bc - want_bc).norm(), 1e-8 * (1.0 + want_bc.norm())) << "trial " << trial;
    EXPECT_LT((got_bb - want_bb).norm(), 1e-8 * (1.0 + want_bb.norm())) << "trial " << trial;
  }
  // What makes it fast: most single columns reach well under half of the factor's rows.
  EXPECT_GT(short_paths, 20);
}

}  // namespace
}  // namespace omnivert::calib::internal
