#include "calib/propagator.hpp"

#include <algorithm>
#include <cmath>

#include "omnivert/calib/model.hpp"

namespace omnivert::calib {

std::array<Eigen::Vector2d, 2> frame_steps(double d_right,
                                           double d_left,
                                           double lateral,
                                           double wheel_base) {
  const Eigen::Vector2d one(d_right, d_left), zero = Eigen::Vector2d::Zero();
  const double e = wheel_base;
  const double along = 0.5 * (d_right + d_left), turn = (d_right - d_left) / e;
  // The displacement in the robot frame at the start: `along` the mid-step heading, `lateral`
  // across it.
  const double mid = 0.5 * turn, c = std::cos(mid), s = std::sin(mid);
  Eigen::Vector2d t(c * along - s * lateral, s * along + c * lateral);
  if (lateral == 0.0 || std::abs(lateral) > 0.5 * std::abs(along)) return {one, zero};
  const double r = along < 0.0 ? -t.norm() : t.norm();  // backwards: r < 0
  if (along < 0.0) t = -t;
  // Second step: distance r with mid-step heading alpha + (turn - alpha) / 2 = psi, the
  // direction of t; first: a turn in place by alpha = 2 psi - turn.
  const double psi = std::atan2(t(1), t(0));
  const double alpha = 2.0 * psi - turn;
  const double rest = turn - alpha;
  return {Eigen::Vector2d(0.5 * e * alpha, -0.5 * e * alpha),
          Eigen::Vector2d(r + 0.5 * e * rest, r - 0.5 * e * rest)};
}

void Propagator::propagate(const FrameInput& frame, FilterState* state) const {
  // A sideways displacement within three sigmas of its own noise (the wheels' noise composed
  // over the frame, and the side slip the batch allows) is noise: one step of eq. (29), as
  // the paper. (Composed from noisy wheel samples nearly every frame has one, about 0.02 mm
  // on the simulator's straights; a straight that turns within the frame has 0.47 mm.)
  const double K = options_.robot.odometry_K * options_.filter.odometry_inflation;
  const double noise = std::sqrt(K * std::max(frame.covariance_per_K(2, 2), 0.0) +
                                 options_.robot.lateral_sigma * options_.robot.lateral_sigma);
  if (std::abs(frame.lateral) <= 3.0 * noise) {
    propagate(frame.d_right, frame.d_left, state);
    return;
  }
  const auto steps =
      frame_steps(frame.d_right, frame.d_left, frame.lateral, options_.robot.wheel_base);
  propagate(steps[0](0), steps[0](1), state);
  if (!steps[1].isZero()) propagate(steps[1](0), steps[1](1), state);
}

void propagate_covariance(const std::vector<TransitionBlock>& F,
                          const Eigen::MatrixXd& G,
                          const Eigen::Matrix2d& Q,
                          Eigen::MatrixXd* P) {
  for (const TransitionBlock& b : F) {
    const Eigen::MatrixXd rows = b.A * P->middleRows(b.index, b.A.rows());
    P->middleRows(b.index, b.A.rows()) = rows;
  }
  for (const TransitionBlock& b : F) {
    const Eigen::MatrixXd cols = P->middleCols(b.index, b.A.rows()) * b.A.transpose();
    P->middleCols(b.index, b.A.rows()) = cols;
  }
  P->noalias() += G * Q * G.transpose();
}

void Propagator::propagate(double d_right, double d_left, FilterState* state) const {
  const int n = state->dim();
  const double e = options_.robot.wheel_base;
  // F_x is block diagonal (A^i per feature, identity for the extrinsics); F_u stacks the
  // B^i with zeros for the extrinsics (appendix A.4).
  std::vector<TransitionBlock> F;
  F.reserve(state->slots().size());
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, 2);
  Eigen::VectorXd& x = state->mutable_x();
  for (const FeatureSlot& s : state->slots()) {
    const int i = s.index;
    switch (s.param) {
      case FeatureParam::kDistance: {  // Eq. (29), A^i and B^i of eq. (32)
        Mat2 A, B;
        x.segment<2>(i) = propagate_feature(x.segment<2>(i), d_right, d_left, e, &A, &B);
        F.push_back({i, A});
        G.block<2, 2>(i, 0) = B;
        break;
      }
      case FeatureParam::kInverseDistance: {  // Eq. (29) in (1/D, theta)
        Mat2 A, B;
        x.segment<2>(i) = propagate_feature_inverse(x.segment<2>(i), d_right, d_left, e, &A, &B);
        F.push_back({i, A});
        G.block<2, 2>(i, 0) = B;
        break;
      }
      case FeatureParam::kPoint: {  // Eq. (14) in the robot frame
        Mat2 A, B;
        x.segment<2>(i) = propagate_point(x.segment<2>(i), d_right, d_left, e, &A, &B);
        F.push_back({i, A});
        G.block<2, 2>(i, 0) = B;
        break;
      }
      case FeatureParam::kAnchored: {
        Mat4 A;
        Mat42 B;
        x.segment<4>(i) = propagate_anchored(x.segment<4>(i), d_right, d_left, e, &A, &B);
        F.push_back({i, A});
        G.block<4, 2>(i, 0) = B;
        break;
      }
    }
  }
  // Eq. (31) with the inflated K.
  const Mat2 Q =
      chong_kleeman_covariance(d_right,
                               d_left,
                               options_.robot.odometry_K * options_.filter.odometry_inflation,
                               options_.robot.odometry_variance_floor);
  propagate_covariance(F, G, Q, &state->mutable_P());
  state->normalise();
}

}  // namespace omnivert::calib
