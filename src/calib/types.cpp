#include "omnivert/calib/types.hpp"

#include <cmath>

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

}  // namespace omnivert::calib
