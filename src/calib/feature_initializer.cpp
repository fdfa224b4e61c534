#include "omnivert/calib/feature_initializer.hpp"

#include "omnivert/calib/model.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

int FeatureInitializer::initialize(int track_id, double beta, int frame,
                                   FilterState* state) const {
  const Extrinsics ex = state->extrinsics();
  const int n = state->dim();
  const int e = state->extrinsics_index();
  const double var_beta = options_.bearing_sigma * options_.bearing_sigma;

  FeatureSlot slot;
  slot.track_id = track_id;
  slot.first_frame = frame;
  slot.last_seen_frame = frame;
  Vec2 y;
  Mat23 G_ex;                // d y / d (phi, rho, psi)
  Mat2 G_n;                  // d y / d (prior variable, beta)
  Eigen::Vector2d var_n;     // variances of (prior variable, beta)
  if (options_.feature_init == FeatureInit::kNaive) {
    // NOTES Sec. 5 "naive": far-feature approximation of eq. (27), beta ~ pi - theta - phi - psi.
    slot.param = FeatureParam::kDistance;
    y << options_.naive_distance, wrap_angle(kPi - beta - ex.phi - ex.psi);
    G_ex << 0, 0, 0, -1, 0, -1;
    G_n << 1, 0, 0, -1;
    var_n << options_.naive_distance_sigma * options_.naive_distance_sigma, var_beta;
  } else {
    slot.param = FeatureParam::kInverseDistance;
    const double q_lo = 1.0 / options_.max_feature_distance;
    const double q_hi = 1.0 / options_.min_feature_distance;
    const double q0 = 0.5 * (q_lo + q_hi);
    const double sigma_q = 0.25 * (q_hi - q_lo);  // the range is +-2 sigma
    y = feature_from_ray(q0, beta, ex, &G_n, &G_ex);
    var_n << sigma_q * sigma_q, var_beta;
  }
  const Eigen::MatrixXd& P = state->P();
  Eigen::Matrix<double, 2, Eigen::Dynamic> P_yx = G_ex * P.middleRows<3>(e);
  Eigen::Matrix2d P_yy = G_ex * P.block<3, 3>(e, e) * G_ex.transpose() +
                         G_n * var_n.asDiagonal() * G_n.transpose();
  (void)n;
  state->add_feature(slot, y, P_yx, P_yy);
  return state->num_features() - 1;
}

}  // namespace omnivert::calib
