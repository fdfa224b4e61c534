#include "calib/filter_state.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "omnivert/calib/model.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

int feature_param_size(FeatureParam p) { return p == FeatureParam::kAnchored ? 4 : 2; }

FilterState::FilterState(const Extrinsics& prior,
                         const Eigen::Vector3d& prior_sigma,
                         ExtrinsicsParam param)
    : ext_param_(param) {
  const Eigen::Matrix3d P0 = prior_sigma.array().square().matrix().asDiagonal();
  if (param == ExtrinsicsParam::kPaper) {
    x_ = prior.vec();
    P_ = P0;
  } else {
    Mat3 J;
    x_ = camera_pose_from_extrinsics(prior, &J);
    P_ = J * P0 * J.transpose();
  }
}

int FilterState::find(int track_id) const {
  for (int i = 0; i < num_features(); ++i)
    if (slots_[i].track_id == track_id) return i;
  return -1;
}

Extrinsics FilterState::extrinsics() const {
  if (ext_param_ == ExtrinsicsParam::kPaper) return Extrinsics::from_vec(x_.tail<3>());
  return extrinsics_from_camera_pose(x_.tail<3>());
}

Eigen::Matrix3d FilterState::extrinsics_covariance() const {
  const Eigen::Matrix3d C = P_.bottomRightCorner<3, 3>();
  if (ext_param_ == ExtrinsicsParam::kPaper) return C;
  Mat3 J;
  extrinsics_from_camera_pose(x_.tail<3>(), &J);
  return J * C * J.transpose();
}

Eigen::Vector2d FilterState::feature_distance_form(int slot, Eigen::Matrix2d* cov) const {
  const FeatureSlot& s = slots_[slot];
  const int ps = feature_param_size(s.param);  // the point's entries (not a bias)
  const Eigen::VectorXd f = x_.segment(s.index, ps);
  const Eigen::MatrixXd C = P_.block(s.index, s.index, ps, ps);
  Eigen::Vector2d out;
  Eigen::MatrixXd J(2, ps);
  switch (s.param) {
    case FeatureParam::kDistance:
      out = f;
      J.setIdentity();
      break;
    case FeatureParam::kInverseDistance:
      out << 1.0 / f(0), f(1);
      J << -1.0 / (f(0) * f(0)), 0, 0, 1;
      break;
    case FeatureParam::kPoint: {
      Mat2 Jd;
      out = point_to_distance_form(f, &Jd);
      J = Jd;
      break;
    }
    case FeatureParam::kAnchored: {
      Eigen::Matrix<double, 2, 4> Jp;
      const Vec2 p = anchored_to_point(f, &Jp);
      Mat2 Jd;
      out = point_to_distance_form(p, &Jd);
      J = Jd * Jp;
      break;
    }
  }
  if (cov) *cov = J * C * J.transpose();
  return out;
}

void FilterState::reindex() {
  int i = 0;
  for (FeatureSlot& s : slots_) {
    s.index = i;
    s.size = feature_param_size(s.param) + (s.bias ? 1 : 0);
    i += s.size;
  }
}

void FilterState::add_feature(FeatureSlot slot,
                              const Eigen::VectorXd& xf,
                              const Eigen::MatrixXd& P_fx,
                              const Eigen::MatrixXd& P_ff) {
  const int n = dim();
  const int k = static_cast<int>(xf.size());
  assert(P_fx.rows() == k && P_fx.cols() == n);
  const int nf = n - 3;  // the new block goes at [nf, nf + k), before the extrinsics
  Eigen::VectorXd x(n + k);
  Eigen::MatrixXd P(n + k, n + k);
  x << x_.head(nf), xf, x_.tail<3>();
  auto map = [nf, k](int i) { return i < nf ? i : i + k; };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) P(map(i), map(j)) = P_(i, j);
    P.block(nf, map(i), k, 1) = P_fx.col(i);
    P.block(map(i), nf, 1, k) = P_fx.col(i).transpose();
  }
  P.block(nf, nf, k, k) = 0.5 * (P_ff + P_ff.transpose());
  x_ = std::move(x);
  P_ = std::move(P);
  assert(k == feature_param_size(slot.param) + (slot.bias ? 1 : 0));
  slot.size = k;
  slots_.push_back(slot);
  reindex();
}

void FilterState::remove_feature(int slot) {
  const int n = dim();
  const int a = slots_[slot].index, k = slots_[slot].size;
  // Marginalising a Gaussian = dropping its rows and columns.
  std::vector<int> keep;
  keep.reserve(n - k);
  for (int i = 0; i < n; ++i)
    if (i < a || i >= a + k) keep.push_back(i);
  const int m = static_cast<int>(keep.size());
  Eigen::VectorXd x(m);
  Eigen::MatrixXd P(m, m);
  for (int i = 0; i < m; ++i) {
    x(i) = x_(keep[i]);
    for (int j = 0; j < m; ++j) P(i, j) = P_(keep[i], keep[j]);
  }
  x_ = std::move(x);
  P_ = std::move(P);
  slots_.erase(slots_.begin() + slot);
  reindex();
}

void FilterState::reparametrise(int slot,
                                FeatureParam param,
                                const Eigen::VectorXd& y,
                                const Eigen::MatrixXd& J) {
  const int n = dim();
  // The parametrisation's entries [a, a + k); a bias entry after them stays (identity).
  const int a = slots_[slot].index, k = feature_param_size(slots_[slot].param);
  const int m = static_cast<int>(y.size());
  assert(J.rows() == m && J.cols() == k);
  // P <- T P T^T with T the identity but for J in the slot's block: only the slot's rows and
  // columns change, O(n k m) instead of the dense O(n^3)
  // (FilterState.ReparametriseEqualsTheDenseProduct).
  const int b = n - a - k;  // entries after the slot
  Eigen::MatrixXd Pn(n - k + m, n - k + m);
  Pn.topLeftCorner(a, a) = P_.topLeftCorner(a, a);
  Pn.topRightCorner(a, b) = P_.topRightCorner(a, b);
  Pn.bottomLeftCorner(b, a) = P_.bottomLeftCorner(b, a);
  Pn.bottomRightCorner(b, b) = P_.bottomRightCorner(b, b);
  Pn.block(0, a, a, m).noalias() = P_.block(0, a, a, k) * J.transpose();
  Pn.block(a, a + m, m, b).noalias() = J * P_.block(a, a + k, k, b);
  Pn.block(a, a, m, m).noalias() = J * P_.block(a, a, k, k) * J.transpose();
  Pn.block(a, 0, m, a) = Pn.block(0, a, a, m).transpose();
  Pn.block(a + m, a, b, m) = Pn.block(a, a + m, m, b).transpose();
  Eigen::VectorXd x(n - k + m);
  x << x_.head(a), y, x_.tail(n - a - k);
  P_ = 0.5 * (Pn + Pn.transpose());
  x_ = std::move(x);
  slots_[slot].param = param;
  reindex();
}

void FilterState::reset(const Eigen::VectorXd& x,
                        const Eigen::MatrixXd& P,
                        std::vector<FeatureSlot> slots) {
  x_ = x;
  P_ = 0.5 * (P + P.transpose());
  slots_ = std::move(slots);
  reindex();
  assert(x_.size() == P_.rows() &&
         (slots_.empty() || slots_.back().index + slots_.back().size == dim() - 3));
}

void FilterState::normalise() {
  for (const FeatureSlot& s : slots_) {
    const int i = s.index;
    // A distance (or inverse distance) pushed non-positive by a bad update is clamped: the
    // feature stays in front of the camera.
    switch (s.param) {
      case FeatureParam::kDistance:
        x_(i) = std::max(x_(i), 1e-3);
        x_(i + 1) = wrap_angle(x_(i + 1));
        break;
      case FeatureParam::kInverseDistance:
        x_(i) = std::max(x_(i), 1e-4);
        x_(i + 1) = wrap_angle(x_(i + 1));
        break;
      case FeatureParam::kPoint:
        break;
      case FeatureParam::kAnchored:
        x_(i + 2) = wrap_angle(x_(i + 2));
        x_(i + 3) = std::max(x_(i + 3), 1e-4);
        break;
    }
  }
  const int e = extrinsics_index();
  if (ext_param_ == ExtrinsicsParam::kPaper) {
    x_(e) = wrap_angle(x_(e));
    x_(e + 2) = wrap_angle(x_(e + 2));
  } else {
    x_(e + 2) = wrap_angle(x_(e + 2));
  }
  P_ = 0.5 * (P_ + P_.transpose()).eval();
}

}  // namespace omnivert::calib
