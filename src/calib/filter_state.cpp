#include "omnivert/calib/filter_state.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

FilterState::FilterState(const Extrinsics& prior, const Eigen::Vector3d& prior_sigma) {
  x_ = prior.vec();
  P_ = prior_sigma.array().square().matrix().asDiagonal();
}

int FilterState::find(int track_id) const {
  for (int i = 0; i < num_features(); ++i)
    if (slots_[i].track_id == track_id) return i;
  return -1;
}

Extrinsics FilterState::extrinsics() const {
  return Extrinsics::from_vec(x_.tail<3>());
}

Eigen::Matrix3d FilterState::extrinsics_covariance() const {
  return P_.bottomRightCorner<3, 3>();
}

Eigen::Vector2d FilterState::feature_distance_form(int slot, Eigen::Matrix2d* cov) const {
  const int i = feature_index(slot);
  Eigen::Vector2d f = x_.segment<2>(i);
  Eigen::Matrix2d C = P_.block<2, 2>(i, i);
  if (slots_[slot].param == FeatureParam::kInverseDistance) {
    const double q = f(0);
    Eigen::Matrix2d J = Eigen::Matrix2d::Identity();
    J(0, 0) = -1.0 / (q * q);
    f(0) = 1.0 / q;
    C = J * C * J.transpose();
  }
  if (cov) *cov = C;
  return f;
}

void FilterState::add_feature(const FeatureSlot& slot, const Eigen::Vector2d& xf,
                              const Eigen::Matrix<double, 2, Eigen::Dynamic>& P_fx,
                              const Eigen::Matrix2d& P_ff) {
  const int n = dim();
  assert(P_fx.cols() == n);
  const int nf = 2 * num_features();  // the new block goes at [nf, nf + 2)
  // Permutation of the old state into the new one: features keep their indices, the
  // extrinsics move two places down.
  auto map = [nf](int i) { return i < nf ? i : i + 2; };
  Eigen::VectorXd x(n + 2);
  Eigen::MatrixXd P(n + 2, n + 2);
  for (int i = 0; i < n; ++i) {
    x(map(i)) = x_(i);
    for (int j = 0; j < n; ++j) P(map(i), map(j)) = P_(i, j);
    P.block<2, 1>(nf, map(i)) = P_fx.col(i);
    P.block<1, 2>(map(i), nf) = P_fx.col(i).transpose();
  }
  x.segment<2>(nf) = xf;
  P.block<2, 2>(nf, nf) = 0.5 * (P_ff + P_ff.transpose());
  x_ = std::move(x);
  P_ = std::move(P);
  slots_.push_back(slot);
}

void FilterState::remove_feature(int slot) {
  const int n = dim();
  const int k = feature_index(slot);
  // Marginalising a Gaussian = dropping its rows and columns.
  std::vector<int> keep;
  keep.reserve(n - 2);
  for (int i = 0; i < n; ++i)
    if (i != k && i != k + 1) keep.push_back(i);
  Eigen::VectorXd x(n - 2);
  Eigen::MatrixXd P(n - 2, n - 2);
  for (int i = 0; i < n - 2; ++i) {
    x(i) = x_(keep[i]);
    for (int j = 0; j < n - 2; ++j) P(i, j) = P_(keep[i], keep[j]);
  }
  x_ = std::move(x);
  P_ = std::move(P);
  slots_.erase(slots_.begin() + slot);
}

void FilterState::convert_to_distance(int slot) {
  FeatureSlot& s = slots_[slot];
  if (s.param == FeatureParam::kDistance) return;
  const int i = feature_index(slot);
  const double q = x_(i);
  const double J = -1.0 / (q * q);  // dD/dq
  x_(i) = 1.0 / q;
  P_.row(i) *= J;
  P_.col(i) *= J;
  s.param = FeatureParam::kDistance;
}

void FilterState::normalise() {
  for (int s = 0; s < num_features(); ++s) {
    const int i = feature_index(s);
    x_(i + 1) = wrap_angle(x_(i + 1));
    // A distance (or inverse distance) pushed non-positive by a bad update is clamped:
    // the feature stays in front of the robot (a rare event, counted by the caller).
    if (slots_[s].param == FeatureParam::kInverseDistance)
      x_(i) = std::max(x_(i), 1e-4);
    else
      x_(i) = std::max(x_(i), 1e-3);
  }
  const int e = extrinsics_index();
  x_(e) = wrap_angle(x_(e));
  x_(e + 2) = wrap_angle(x_(e + 2));
  P_ = 0.5 * (P_ + P_.transpose()).eval();
}

}  // namespace omnivert::calib
