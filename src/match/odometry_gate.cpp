#include "omnivert/match/odometry_gate.hpp"

#include <cmath>

#include "omnivert/core/angles.hpp"

namespace omnivert {

bool OdometryGateOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (!enabled) return true;
  if (!(std::isfinite(wheel_base) && wheel_base > 0.0)) {
    return fail("odometry gate: the wheel base e must be positive (metres)");
  }
  if (!(std::isfinite(min_feature_distance) && min_feature_distance > 0.0)) {
    return fail("odometry gate: the minimum feature distance must be positive (metres)");
  }
  if (!(std::isfinite(max_camera_offset) && max_camera_offset >= 0.0)) {
    return fail("odometry gate: the maximum camera offset rho_max must be >= 0 (metres)");
  }
  if (!(std::isfinite(bearing_tolerance) && bearing_tolerance >= 0.0)) {
    return fail("odometry gate: the bearing tolerance must be >= 0 (radians)");
  }
  if (!(std::isfinite(slip_fraction) && slip_fraction >= 0.0)) {
    return fail("odometry gate: the slip fraction must be >= 0");
  }
  return true;
}

void OdometryAccumulator::add(const WheelIncrement& inc, double wheel_base) {
  // Eqs. (14)-(15): the travel along the heading midway through the increment.
  const double d_theta = (inc.d_right - inc.d_left) / wheel_base;
  const double d_rho = 0.5 * (inc.d_right + inc.d_left);
  x += d_rho * std::cos(theta + 0.5 * d_theta);
  y += d_rho * std::sin(theta + 0.5 * d_theta);
  theta += d_theta;
  path_length += std::abs(d_rho);
  wheel_travel += std::abs(inc.d_right) + std::abs(inc.d_left);
}

bool BearingGate::admits(double bearing_before, double bearing_after) const {
  if (!informative) return true;
  return std::abs(angle_diff(bearing_after, bearing_before + predicted_change)) <= max_deviation;
}

BearingGate make_bearing_gate(const OdometryGateOptions& options,
                              const OdometryAccumulator& before,
                              const OdometryAccumulator& after) {
  BearingGate g;
  const double d_theta = after.theta - before.theta;
  // The camera turns with the robot: bearings of static lines shift by -d_theta (eq. 16).
  g.predicted_change = -d_theta;
  // Bound on the camera-centre displacement: chord <= path of the axle midpoint, plus the
  // swing of an offset of at most rho_max under the rotation d_theta.
  const double s = (after.path_length - before.path_length) +
                   2.0 * options.max_camera_offset * std::abs(std::sin(0.5 * d_theta));
  if (s >= options.min_feature_distance) {
    g.informative = false;
    g.max_deviation = kPi;
    return g;
  }
  const double parallax = std::asin(s / options.min_feature_distance);
  const double slip =
      options.slip_fraction * (after.wheel_travel - before.wheel_travel) / options.wheel_base;
  g.max_deviation = parallax + slip + options.bearing_tolerance;
  g.informative = g.max_deviation < kPi;
  if (!g.informative) g.max_deviation = kPi;
  return g;
}

}  // namespace omnivert
