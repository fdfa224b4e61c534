#pragma once
// Angle helpers. Every difference of two angles in omnivert (innovations, matching gates,
// bearing errors) goes through wrap_angle (docs/theory/conventions.md): bearings are circular.

#include <cmath>
#include <numbers>

namespace omnivert {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

constexpr double deg2rad(double deg) { return deg * (kPi / 180.0); }
constexpr double rad2deg(double rad) { return rad * (180.0 / kPi); }

// Wraps an angle to (-pi, pi].
inline double wrap_angle(double a) {
  double w = std::remainder(a, kTwoPi);  // in [-pi, pi]
  if (w <= -kPi) w += kTwoPi;
  return w;
}

// Wraps an angle to [0, 2 pi).
inline double wrap_positive(double a) {
  double w = std::fmod(a, kTwoPi);
  if (w < 0.0) w += kTwoPi;
  if (w >= kTwoPi) w -= kTwoPi;
  return w;
}

// Signed smallest difference a - b, in (-pi, pi].
inline double angle_diff(double a, double b) { return wrap_angle(a - b); }

}  // namespace omnivert
