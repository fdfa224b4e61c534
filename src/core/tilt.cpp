#include "omnivert/core/tilt.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace omnivert {

Eigen::Matrix3d tilt_rotation(double tilt, double direction) {
  const Eigen::Vector3d k(-std::sin(direction), std::cos(direction), 0.0);
  return Eigen::AngleAxisd(tilt, k).toRotationMatrix();
}

Eigen::Matrix3d tilt_rotation_of_vector(const Eigen::Vector2d& tilt_vector) {
  const double t = tilt_vector.norm();
  if (t == 0.0) return Eigen::Matrix3d::Identity();
  return tilt_rotation(t, std::atan2(tilt_vector.y(), tilt_vector.x()));
}

Eigen::Vector3d unit_direction(double beta, double el) {
  const double c = std::cos(el);
  return {c * std::cos(beta), c * std::sin(beta), std::sin(el)};
}

}  // namespace omnivert
