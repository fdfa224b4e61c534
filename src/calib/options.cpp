#include "omnivert/calib/options.hpp"

#include <cmath>

#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

namespace {
bool fail(std::string* why, const std::string& msg) {
  if (why) *why = msg;
  return false;
}
bool finite_positive(double v) { return std::isfinite(v) && v > 0.0; }
bool finite_non_negative(double v) { return std::isfinite(v) && v >= 0.0; }

bool robot_valid(const RobotModel& r, std::string* why) {
  if (!finite_positive(r.wheel_base)) return fail(why, "robot.wheel_base must be > 0 [m]");
  if (!finite_non_negative(r.odometry_K))
    return fail(why, "robot.odometry_K (Chong-Kleeman K, eq. 31) must be >= 0 [m]");
  if (!finite_positive(r.odometry_variance_floor))
    return fail(why, "robot.odometry_variance_floor must be > 0 [m^2]");
  if (!finite_positive(r.lateral_sigma)) return fail(why, "robot.lateral_sigma must be > 0 [m]");
  return true;
}

bool noise_and_prior_valid(const CalibrationOptions& o, std::string* why) {
  if (!finite_positive(o.noise.bearing_sigma))
    return fail(why, "noise.bearing_sigma must be > 0 [rad]");
  if (!finite_non_negative(o.noise.track_bias_sigma))
    return fail(why, "noise.track_bias_sigma must be >= 0 [rad] (0: no per-track bias)");
  const Extrinsics& m = o.prior.mean;
  if (!std::isfinite(m.phi) || !std::isfinite(m.psi) || !finite_positive(m.rho))
    return fail(why, "prior.mean: phi and psi must be finite and rho > 0");
  for (int i = 0; i < 3; ++i)
    if (!finite_positive(o.prior.sigma(i)))
      return fail(why, "prior.sigma: the sigmas of phi, rho, psi must all be > 0");
  return true;
}

bool filter_valid(const CalibrationOptions& o, std::string* why) {
  const FilterOptions& f = o.filter;
  if (!finite_positive(f.odometry_inflation))
    return fail(why, "filter.odometry_inflation must be > 0");
  if (!finite_positive(f.naive_distance) || !finite_positive(f.naive_distance_sigma))
    return fail(why, "filter.naive_distance and filter.naive_distance_sigma must be > 0 [m]");
  if (!finite_positive(f.min_feature_distance) ||
      !(f.max_feature_distance > f.min_feature_distance))
    return fail(why,
                "filter: need 0 < min_feature_distance < max_feature_distance (filter."
                "min_feature_distance, filter.max_feature_distance)");
  if (!(o.prior.mean.rho < f.min_feature_distance))
    return fail(why, "filter.min_feature_distance must exceed the camera offset prior.mean.rho");
  if (!finite_non_negative(f.convert_ratio))
    return fail(why, "filter.convert_ratio must be >= 0 (0: never convert)");
  if (!std::isfinite(f.bootstrap_rotation))
    return fail(why, "filter.bootstrap_rotation must be finite");
  if (f.bootstrap_min_frames < 2 || f.bootstrap_max_frames < f.bootstrap_min_frames)
    return fail(why,
                "filter: need 2 <= bootstrap_min_frames <= bootstrap_max_frames (filter."
                "bootstrap_min_frames, filter.bootstrap_max_frames)");
  if (f.bootstrap_starts < 1 || f.bootstrap_starts > 5)
    return fail(why, "filter.bootstrap_starts must be between 1 and 5");
  if (!finite_positive(f.bootstrap_depth_prior_scale))
    return fail(why, "filter.bootstrap_depth_prior_scale must be > 0");
  if (f.update_iterations < 1) return fail(why, "filter.update_iterations must be >= 1");
  return true;
}

bool association_valid(const AssociationOptions& a, std::string* why) {
  if (!(a.gate_probability > 0.0 && a.gate_probability <= 1.0))
    return fail(why, "association.gate_probability must be in (0, 1]");
  if (a.max_missed_frames < 0) return fail(why, "association.max_missed_frames must be >= 0");
  if (!(a.join_prediction_sigmas >= 0.0))
    return fail(why, "association.join_prediction_sigmas must be >= 0 (0: no limit)");
  if (a.min_track_length < 2) return fail(why, "association.min_track_length must be >= 2");
  if (!finite_non_negative(a.min_feature_range))
    return fail(why, "association.min_feature_range must be >= 0 [m]");
  if (!(a.crossing_guard >= 0.0 && a.crossing_guard < 0.5))
    return fail(why, "association.crossing_guard must be >= 0 and below 0.5 rad");
  if (!finite_non_negative(a.split_chi2))
    return fail(why, "association.split_chi2 must be >= 0 and finite");
  if (a.split_min_bearings < 1) return fail(why, "association.split_min_bearings must be >= 1");
  if (!(a.split_keep_fraction > 0.0 && a.split_keep_fraction <= 1.0))
    return fail(why, "association.split_keep_fraction must be in (0, 1]");
  if (a.split_rounds < 0) return fail(why, "association.split_rounds must be >= 0");
  return true;
}

bool checks_valid(const CalibrationOptions& o, std::string* why) {
  const RefinementOptions& r = o.refinement;
  if (!finite_positive(r.odometry_inflation))
    return fail(why, "refinement.odometry_inflation must be > 0");
  if (!finite_positive(r.huber_sigmas)) return fail(why, "refinement.huber_sigmas must be > 0");
  if (r.max_iterations < 1) return fail(why, "refinement.max_iterations must be >= 1");
  if (!(r.association_function_tolerance > 0.0 && r.association_function_tolerance < 1.0))
    return fail(why, "refinement.association_function_tolerance must be in (0, 1)");
  if (r.warm_start_window < 0)
    return fail(why, "refinement.warm_start_window must be >= 0 (0: off)");
  if (r.warm_start_window > 0 &&
      !(r.warm_start_overlap >= 1 && r.warm_start_overlap < r.warm_start_window))
    return fail(why, "refinement.warm_start_overlap must be in [1, warm_start_window)");
  if (!finite_positive(r.time_offset_prior_sigma_s))
    return fail(why, "refinement.time_offset_prior_sigma_s must be > 0 [s]");
  const NoiseCheckOptions& n = o.noise_check;
  if (!(n.level > 0.0 && n.level < 0.5)) return fail(why, "noise_check.level must be in (0, 0.5)");
  if (!(n.lower_level >= 0.0 && n.lower_level < 0.5))
    return fail(why, "noise_check.lower_level must be in [0, 0.5) (0: that side off)");
  if (std::isnan(n.lower_max_joins))
    return fail(why, "noise_check.lower_max_joins must be a number (< 0: never applied)");
  if (n.dense_limit < 0) return fail(why, "noise_check.dense_limit must be >= 0");
  if (n.dense_track_limit < 0) return fail(why, "noise_check.dense_track_limit must be >= 0");
  if (o.threads < 0) return fail(why, "threads must be >= 0 (0: every core)");
  const ObservabilityOptions& b = o.observability;
  if (!finite_positive(b.max_sigma_angle) || !finite_positive(b.max_sigma_rho))
    return fail(why, "observability.max_sigma_angle and observability.max_sigma_rho must be > 0");
  if (!finite_non_negative(b.relative_eigenvalue_floor))
    return fail(why, "observability.relative_eigenvalue_floor must be >= 0");
  if (!finite_non_negative(b.min_rotation_sigmas))
    return fail(why, "observability.min_rotation_sigmas must be >= 0");
  return true;
}
}  // namespace

bool CalibrationOptions::IsValid(std::string* why) const {
  return robot_valid(robot, why) && noise_and_prior_valid(*this, why) && filter_valid(*this, why) &&
         association_valid(association, why) && checks_valid(*this, why);
}

CalibrationOptions recommended_options() { return CalibrationOptions{}; }

CalibrationOptions paper_options() {
  CalibrationOptions o;
  o.noise.bearing_sigma = deg2rad(0.3);
  o.filter.odometry_inflation = 5.0;
  return o;
}

}  // namespace omnivert::calib
