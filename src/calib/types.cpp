#include "omnivert/calib/types.hpp"

#include <cmath>
#include <sstream>

#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

Eigen::Vector2d Extrinsics::position() const { return {rho * std::cos(phi), rho * std::sin(phi)}; }

double Extrinsics::yaw() const { return wrap_angle(phi + psi); }

Eigen::Matrix4d Extrinsics::T_base_cam() const {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  const double y = phi + psi;
  T(0, 0) = std::cos(y);
  T(0, 1) = -std::sin(y);
  T(1, 0) = std::sin(y);
  T(1, 1) = std::cos(y);
  T.block<2, 1>(0, 3) = position();
  return T;
}

namespace {
bool fail(std::string* why, const std::string& msg) {
  if (why) *why = msg;
  return false;
}
bool finite_positive(double v) { return std::isfinite(v) && v > 0.0; }
}  // namespace

bool Options::IsValid(std::string* why) const {
  if (!finite_positive(wheel_base)) return fail(why, "wheel_base must be > 0 [m]");
  if (!std::isfinite(odometry_K) || odometry_K < 0.0)
    return fail(why, "odometry_K (Chong-Kleeman K, eq. 31) must be >= 0 [m]");
  if (!finite_positive(odometry_inflation)) return fail(why, "odometry_inflation must be > 0");
  if (!std::isfinite(odometry_variance_floor) || odometry_variance_floor <= 0.0)
    return fail(why, "odometry_variance_floor must be > 0 [m^2]");
  if (!finite_positive(bearing_sigma)) return fail(why, "bearing_sigma must be > 0 [rad]");
  if (!(std::isfinite(track_bias_sigma) && track_bias_sigma >= 0.0))
    return fail(why, "track_bias_sigma must be >= 0 [rad] (0: no per-track bias)");
  if (!std::isfinite(prior.phi) || !std::isfinite(prior.psi) || !finite_positive(prior.rho))
    return fail(why, "prior: phi and psi must be finite and rho > 0");
  for (int i = 0; i < 3; ++i)
    if (!finite_positive(prior_sigma(i)))
      return fail(why, "prior sigmas of phi, rho, psi must all be > 0");
  if (!finite_positive(naive_distance) || !finite_positive(naive_distance_sigma))
    return fail(why, "naive_distance and naive_distance_sigma must be > 0 [m]");
  if (!(std::isfinite(min_feature_range) && min_feature_range >= 0.0))
    return fail(why, "min_feature_range must be >= 0");
  if (!finite_positive(min_feature_distance) || !(max_feature_distance > min_feature_distance))
    return fail(why, "need 0 < min_feature_distance < max_feature_distance");
  if (!(prior.rho < min_feature_distance))
    return fail(why, "min_feature_distance must exceed the camera offset rho");
  if (!std::isfinite(convert_ratio) || convert_ratio < 0.0)
    return fail(why, "convert_ratio must be >= 0 (0: never convert)");
  if (!std::isfinite(bootstrap_rotation)) return fail(why, "bootstrap_rotation must be finite");
  if (bootstrap_min_frames < 2 || bootstrap_max_frames < bootstrap_min_frames)
    return fail(why, "need 2 <= bootstrap_min_frames <= bootstrap_max_frames");
  if (bootstrap_starts < 1 || bootstrap_starts > 5)
    return fail(why, "bootstrap_starts must be between 1 and 5");
  if (!finite_positive(lateral_sigma)) return fail(why, "lateral_sigma must be > 0");
  if (!(split_chi2 >= 0.0 && std::isfinite(split_chi2)))
    return fail(why, "split_chi2 must be >= 0 and finite");
  if (!finite_positive(bootstrap_depth_prior_scale))
    return fail(why, "bootstrap_depth_prior_scale must be > 0");
  if (update_iterations < 1) return fail(why, "update_iterations must be >= 1");
  if (!(gate_probability > 0.0 && gate_probability <= 1.0))
    return fail(why, "gate_probability must be in (0, 1]");
  if (max_missed_frames < 0) return fail(why, "max_missed_frames must be >= 0");
  if (min_track_length < 2) return fail(why, "min_track_length must be >= 2");
  if (!(crossing_guard >= 0.0 && crossing_guard < 0.5))
    return fail(why, "crossing_guard must be >= 0 and below 0.5 rad");
  return true;
}

Options recommended_options() {
  Options o;
  o.bearing_sigma = deg2rad(0.025);
  o.track_bias_sigma = 0.0;
  return o;
}

Options paper_options() {
  Options o;
  o.bearing_sigma = deg2rad(0.3);
  o.odometry_inflation = 5.0;
  return o;
}

}  // namespace omnivert::calib
