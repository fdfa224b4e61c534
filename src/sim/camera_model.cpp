#include "omnivert/sim/camera_model.hpp"

#include <cmath>

namespace omnivert::sim {

double CatadioptricCamera::radius_of_elevation(double el) const {
  return gamma * std::cos(el) / (xi - std::sin(el));
}

double CatadioptricCamera::elevation_of_radius(double r) const {
  // r (xi - sin el) = gamma cos el  <=>  r sin el + gamma cos el = r xi
  // <=>  R sin(el + p) = r xi  with R = hypot(r, gamma), p = atan2(gamma, r).
  // The branch el + p = asin(r xi / R) gives el = -pi/2 at r = 0 and el -> asin(xi) as
  // r -> infinity: it is the monotonic one.
  const double R = std::hypot(r, gamma);
  return std::asin(r * xi / R) - std::atan2(gamma, r);
}

Eigen::Vector2d CatadioptricCamera::pixel_of(double bearing, double elevation) const {
  const double r = radius_of_elevation(elevation);
  const double a = bearing_sign * bearing;
  return {cx + r * std::cos(a), cy + r * std::sin(a)};
}

bool CatadioptricCamera::project(const Eigen::Vector3d& p, Eigen::Vector2d& px) const {
  const double h = std::hypot(p.x(), p.y());
  const double n = p.norm();
  if (n == 0.0) return false;
  // Unit sphere, optical axis down (z_m = -z): denominator z_s + xi = xi - z / n.
  const double den = xi - p.z() / n;
  if (den <= 0.0) return false;
  const double r = gamma * (h / n) / den;
  const double a = bearing_sign * std::atan2(p.y(), p.x());
  px = {cx + r * std::cos(a), cy + r * std::sin(a)};
  return true;
}

CameraGeometry CatadioptricCamera::geometry() const {
  CameraGeometry g;
  g.width = width;
  g.height = height;
  g.center = Eigen::Vector2d(cx, cy);
  g.r_min = r_min;
  g.r_max = r_max;
  g.bearing_sign = bearing_sign;
  g.xi = xi;
  g.gamma = gamma;
  return g;
}

std::string CatadioptricCamera::validate() const {
  if (width < 16 || height < 16) return "image size must be at least 16x16 pixels";
  if (!(xi > 0.0 && xi < 1.0)) return "xi must lie in (0, 1)";
  if (!(gamma > 0.0)) return "gamma must be positive";
  if (!(r_min > 0.0 && r_min < r_max)) return "need 0 < r_min < r_max";
  if (bearing_sign != 1 && bearing_sign != -1) return "bearing_sign must be 1 or -1";
  if (!(tilt_deg >= 0.0 && tilt_deg <= 10.0)) return "tilt_deg must lie in [0, 10]";
  if (!std::isfinite(tilt_direction_deg)) return "tilt_direction_deg must be a number";
  const double rim = r_max + 6.0;
  if (cx - rim < 0 || cy - rim < 0 || cx + rim > width || cy + rim > height) {
    return "the mirror rim (r_max + 6 px around the centre) must lie inside the image";
  }
  return {};
}

}  // namespace omnivert::sim
