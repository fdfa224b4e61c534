#include "calib/feature_initializer.hpp"

#include <cmath>

#include "omnivert/calib/model.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

int FeatureInitializer::initialize(
    int track_id, double beta, int frame, FilterState* state, double sigma_scale) const {
  const Extrinsics ex = state->extrinsics();
  const int n = state->dim();
  const int e = state->extrinsics_index();
  const double var_beta = std::pow(options_.noise.bearing_sigma * sigma_scale, 2);

  FeatureSlot slot;
  slot.track_id = track_id;
  slot.first_frame = frame;
  slot.last_seen_frame = frame;
  const double q_lo = 1.0 / options_.filter.max_feature_distance;
  const double q_hi = 1.0 / options_.filter.min_feature_distance;
  const double q0 = 0.5 * (q_lo + q_hi);
  const double sigma_q = 0.25 * (q_hi - q_lo);  // the range is +-2 sigma
  Eigen::VectorXd y;
  Eigen::MatrixXd G_ex;   // d y / d (extrinsics block)
  Eigen::MatrixXd G_n;    // d y / d (prior variable, beta)
  Eigen::Vector2d var_n;  // variances of (prior variable, beta)
  switch (options_.filter.feature_init) {
    case FeatureInit::kNaive: {
      // docs/theory/filter.md "naive": far-feature approximation of eq. (27),
      // beta ~ pi - theta - phi - psi, and a fixed distance prior.
      slot.param = FeatureParam::kDistance;
      y = Eigen::Vector2d(options_.filter.naive_distance, wrap_angle(kPi - beta - ex.phi - ex.psi));
      G_ex = (Eigen::Matrix<double, 2, 3>() << 0, 0, 0, -1, 0, -1).finished();
      G_n = (Eigen::Matrix2d() << 1, 0, 0, -1).finished();
      var_n << options_.filter.naive_distance_sigma * options_.filter.naive_distance_sigma,
          var_beta;
      break;
    }
    case FeatureInit::kInverseDistance: {
      slot.param = FeatureParam::kInverseDistance;
      Mat2 Gn;
      Mat23 Ge;
      y = feature_from_ray(q0, beta, ex, &Gn, &Ge);
      G_n = Gn;
      G_ex = Ge;
      var_n << sigma_q * sigma_q, var_beta;
      break;
    }
    case FeatureInit::kAnchoredInverseDepth: {
      // Anchor at the camera centre, azimuth alpha = beta + eta in the robot frame, inverse
      // depth q0 along the ray.
      slot.param = FeatureParam::kAnchored;
      const Eigen::Vector3d cam = state->x().tail<3>();
      y = Eigen::Vector4d(cam(0), cam(1), wrap_angle(beta + cam(2)), q0);
      G_ex = Eigen::MatrixXd::Zero(4, 3);
      G_ex(0, 0) = G_ex(1, 1) = G_ex(2, 2) = 1.0;
      G_n = Eigen::MatrixXd::Zero(4, 2);
      G_n(3, 0) = 1.0;
      G_n(2, 1) = 1.0;
      var_n << sigma_q * sigma_q, var_beta;
      break;
    }
  }
  Eigen::VectorXd var_noise = var_n;
  if (options_.noise.track_bias_sigma > 0.0) {
    // The track's constant bearing error b (CalibrationOptions::noise.track_bias_sigma) enters as
    // one more entry, at 0 with its prior. The first bearing is eq. (30) + b + noise, so the block
    // was computed from beta - b: its column for b is minus the column for beta, and the block and
    // b start correlated.
    slot.bias = true;
    const int k = static_cast<int>(y.size());
    y.conservativeResize(k + 1);
    y(k) = 0.0;
    G_ex.conservativeResize(k + 1, Eigen::NoChange);
    G_ex.row(k).setZero();
    Eigen::MatrixXd G(k + 1, 3);
    G.setZero();
    G.topLeftCorner(k, 2) = G_n;
    G.block(0, 2, k, 1) = -G_n.col(1);
    G(k, 2) = 1.0;
    G_n = G;
    var_noise = Eigen::Vector3d(var_n(0), var_n(1), std::pow(options_.noise.track_bias_sigma, 2));
  }
  const Eigen::MatrixXd& P = state->P();
  const Eigen::MatrixXd P_yx = G_ex * P.middleRows(e, 3);
  const Eigen::MatrixXd P_yy = G_ex * P.block(e, e, 3, 3) * G_ex.transpose() +
                               G_n * var_noise.asDiagonal() * G_n.transpose();
  (void)n;
  state->add_feature(slot, y, P_yx, P_yy);
  return state->num_features() - 1;
}

}  // namespace omnivert::calib
