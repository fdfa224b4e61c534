#include "omnivert/calib/propagator.hpp"

#include "omnivert/calib/model.hpp"

namespace omnivert::calib {

void Propagator::propagate(double d_right, double d_left, FilterState* state) const {
  const int n = state->dim();
  // F_x is block diagonal (A^i per feature, identity for phi, rho, psi); F_u stacks the
  // B^i with zeros for the extrinsics (appendix A.4).
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(n, n);
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, 2);
  Eigen::VectorXd& x = state->mutable_x();
  for (int s = 0; s < state->num_features(); ++s) {
    const int i = FilterState::feature_index(s);
    Mat2 A, B;
    const Vec2 xi = x.segment<2>(i);
    const Vec2 out =
        state->slots()[s].param == FeatureParam::kDistance
            ? propagate_feature(xi, d_right, d_left, options_.wheel_base, &A, &B)  // Eq. (29)
            : propagate_feature_inverse(xi, d_right, d_left, options_.wheel_base, &A, &B);
    x.segment<2>(i) = out;
    F.block<2, 2>(i, i) = A;
    G.block<2, 2>(i, 0) = B;
  }
  // Eq. (31) with the inflated K.
  const Mat2 Q = chong_kleeman_covariance(d_right, d_left,
                                          options_.odometry_K * options_.odometry_inflation,
                                          options_.odometry_variance_floor);
  Eigen::MatrixXd& P = state->mutable_P();
  P = (F * P * F.transpose() + G * Q * G.transpose()).eval();
  state->normalise();
}

}  // namespace omnivert::calib
