// The filter's linear algebra: each fast path (sparse H, block-diagonal F, a block's change of
// parametrisation) against the dense product it replaces, and the Joseph update's invariants.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>
#include <vector>

#include "calib/feature_initializer.hpp"
#include "calib/filter_state.hpp"
#include "calib/propagator.hpp"
#include "calib/updater.hpp"
#include "omnivert/calib/options.hpp"

namespace omnivert::calib {
namespace {

TEST(Updater, JosephUpdateKeepsCovarianceSymmetricPositiveDefinite) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(6, 6);
  Eigen::MatrixXd P = A * A.transpose() + 1e-3 * Eigen::MatrixXd::Identity(6, 6);
  const Eigen::MatrixXd H = Eigen::MatrixXd::Random(2, 6);
  const Eigen::MatrixXd R = 1e-8 * Eigen::MatrixXd::Identity(2, 2);  // nearly exact
  const Eigen::MatrixXd P0 = P;
  Eigen::MatrixXd K;
  ASSERT_TRUE(joseph_update(H, R, &P, &K));
  EXPECT_LT((P - P.transpose()).norm(), 1e-14);
  EXPECT_EQ(Eigen::LLT<Eigen::MatrixXd>(P).info(), Eigen::Success);
  // Same as the textbook form (I - K H) P0 for the optimal gain.
  EXPECT_LT((P - (Eigen::MatrixXd::Identity(6, 6) - K * H) * P0).norm(), 1e-6 * P0.norm());
}

// The filter's update with H sparse and R diagonal equals the dense Joseph update (its plain
// reference) on a state of 3 extrinsics and 20 two-parameter features, 12 bearings each
// touching one feature and the extrinsics.
TEST(Updater, SparseJosephUpdateEqualsTheDenseOne) {
  const int n = 43, m = 12;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = u(rng);
  Eigen::MatrixXd P = A * A.transpose() + 1e-2 * Eigen::MatrixXd::Identity(n, n);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m, n);
  Eigen::VectorXd r(m);
  for (int k = 0; k < m; ++k) {
    const int f = 3 + 2 * ((k * 7) % 20);
    H(k, f) = u(rng);
    H(k, f + 1) = u(rng);
    for (int e = 0; e < 3; ++e) H(k, e) = u(rng);
    r(k) = 1e-4 * (1.0 + k);
  }
  Eigen::MatrixXd dense = P, sparse = P;
  ASSERT_TRUE(joseph_update(H, Eigen::MatrixXd(r.asDiagonal()), &dense));
  ASSERT_TRUE(joseph_update(Eigen::SparseMatrix<double>(H.sparseView()), r, &sparse));
  EXPECT_LT((sparse - dense).norm(), 1e-12 * dense.norm());
  EXPECT_GT((sparse - P).norm(), 1e-3 * P.norm());  // it did update
  // Not positive definite: refused, P untouched.
  Eigen::VectorXd negative = -1e3 * Eigen::VectorXd::Ones(m);
  Eigen::MatrixXd kept = P;
  EXPECT_FALSE(joseph_update(Eigen::SparseMatrix<double>(H.sparseView()), negative, &kept));
  EXPECT_EQ(kept, P);
}

// The propagation's covariance by F's diagonal blocks equals F P F^T + G Q G^T formed densely
// (its plain reference): 3 extrinsics, then 2x2 and 4x4 feature blocks and a bias left as is.
TEST(Propagator, BlockCovarianceEqualsTheDenseProduct) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random = [&](int r, int c) {
    Eigen::MatrixXd M(r, c);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < c; ++j) M(i, j) = u(rng);
    return M;
  };
  const std::vector<TransitionBlock> F = {
      {3, random(2, 2)}, {5, random(4, 4)}, {9, random(2, 2)}, {12, random(2, 2)}};
  const int n = 15;  // index 11 (a bias) and 14 unchanged
  const Eigen::MatrixXd A = random(n, n);
  const Eigen::MatrixXd P0 = A * A.transpose();
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, 2);
  for (const TransitionBlock& b : F) G.middleRows(b.index, b.A.rows()) = random(b.A.rows(), 2);
  const Eigen::Matrix2d Q = Eigen::Vector2d(2e-5, 3e-5).asDiagonal();
  Eigen::MatrixXd dense_F = Eigen::MatrixXd::Identity(n, n);
  for (const TransitionBlock& b : F) dense_F.block(b.index, b.index, b.A.rows(), b.A.rows()) = b.A;
  const Eigen::MatrixXd reference = dense_F * P0 * dense_F.transpose() + G * Q * G.transpose();
  Eigen::MatrixXd P = P0;
  propagate_covariance(F, G, Q, &P);
  EXPECT_LT((P - reference).norm(), 1e-13 * reference.norm());
  EXPECT_GT((P - P0).norm(), 1e-2 * P0.norm());
}

// The change of a block's parametrisation by its rows and columns equals T P T^T formed densely
// (its plain reference), for the middle one of three anchored features (4 -> 2 entries, the
// state shrinks) with a random positive definite P.
TEST(FilterState, ReparametriseEqualsTheDenseProduct) {
  CalibrationOptions o;
  FilterState state(o.prior.mean, o.prior.sigma, ExtrinsicsParam::kCameraPose);
  const FeatureInitializer init(o);
  for (int id = 0; id < 3; ++id) init.initialize(id, 0.3 + id, 0, &state);
  const int n = state.dim();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = u(rng);
  state.mutable_P() = A * A.transpose();
  const FeatureSlot s = state.slots()[1];
  ASSERT_EQ(s.size, 4);
  Eigen::MatrixXd J(2, 4);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 4; ++j) J(i, j) = u(rng);
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(n - 2, n);
  T.topLeftCorner(s.index, s.index).setIdentity();
  T.block(s.index, s.index, 2, 4) = J;
  T.bottomRightCorner(n - s.index - 4, n - s.index - 4).setIdentity();
  const Eigen::MatrixXd reference = T * state.P() * T.transpose();
  state.reparametrise(1, FeatureParam::kPoint, Eigen::Vector2d(0.5, -0.2), J);
  ASSERT_EQ(state.dim(), n - 2);
  EXPECT_LT((state.P() - reference).norm(), 1e-13 * reference.norm());
  EXPECT_EQ(state.x().segment<2>(s.index), Eigen::Vector2d(0.5, -0.2));
}

}  // namespace
}  // namespace omnivert::calib
