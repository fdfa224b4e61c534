#include "omnivert/calib/propagator.hpp"

#include "omnivert/calib/model.hpp"

namespace omnivert::calib {

void Propagator::propagate(double d_right, double d_left, FilterState* state) const {
  const int n = state->dim();
  const double e = options_.wheel_base;
  // F_x is block diagonal (A^i per feature, identity for the extrinsics); F_u stacks the
  // B^i with zeros for the extrinsics (appendix A.4).
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(n, n);
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, 2);
  Eigen::VectorXd& x = state->mutable_x();
  for (const FeatureSlot& s : state->slots()) {
    const int i = s.index;
    switch (s.param) {
      case FeatureParam::kDistance: {  // Eq. (29), A^i and B^i of eq. (32)
        Mat2 A, B;
        x.segment<2>(i) = propagate_feature(x.segment<2>(i), d_right, d_left, e, &A, &B);
        F.block<2, 2>(i, i) = A;
        G.block<2, 2>(i, 0) = B;
        break;
      }
      case FeatureParam::kInverseDistance: {  // Eq. (29) in (1/D, theta)
        Mat2 A, B;
        x.segment<2>(i) = propagate_feature_inverse(x.segment<2>(i), d_right, d_left, e, &A, &B);
        F.block<2, 2>(i, i) = A;
        G.block<2, 2>(i, 0) = B;
        break;
      }
      case FeatureParam::kPoint: {  // Eq. (14) in the robot frame
        Mat2 A, B;
        x.segment<2>(i) = propagate_point(x.segment<2>(i), d_right, d_left, e, &A, &B);
        F.block<2, 2>(i, i) = A;
        G.block<2, 2>(i, 0) = B;
        break;
      }
      case FeatureParam::kAnchored: {
        Mat4 A;
        Mat42 B;
        x.segment<4>(i) = propagate_anchored(x.segment<4>(i), d_right, d_left, e, &A, &B);
        F.block<4, 4>(i, i) = A;
        G.block<4, 2>(i, 0) = B;
        break;
      }
    }
  }
  // Eq. (31) with the inflated K.
  const Mat2 Q = chong_kleeman_covariance(d_right,
                                          d_left,
                                          options_.odometry_K * options_.odometry_inflation,
                                          options_.odometry_variance_floor);
  Eigen::MatrixXd& P = state->mutable_P();
  P = (F * P * F.transpose() + G * Q * G.transpose()).eval();
  state->normalise();
}

}  // namespace omnivert::calib
