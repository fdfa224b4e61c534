#pragma once
// The motion and observation models of the self-calibration filter (paper Sec. 7, 8.2 and
// appendix A.4), one feature at a time. Jacobians are optional out-parameters named
// J_out_in (d out / d in), computed only when asked for.
//
// Feature state (eq. 19): D = distance from the robot origin to the feature,
// theta = theta_R - atan2(y_R - y_f, x_R - x_f). In the robot frame the feature is at
// (-D cos theta, D sin theta).

#include <Eigen/Core>

#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;
using Row5 = Eigen::Matrix<double, 1, 5>;
using Mat23 = Eigen::Matrix<double, 2, 3>;

// Eq. (15): d_rho = (d_R + d_L) / 2, d_theta = (d_R - d_L) / e. Returns (d_rho, d_theta).
Vec2 wheel_step(double d_right, double d_left, double wheel_base, Mat2* J_step_wheels = nullptr);

// Eq. (14): pose (x, y, theta) after one odometry step (midpoint heading).
Eigen::Vector3d integrate_pose(const Eigen::Vector3d& pose, double d_right, double d_left,
                               double wheel_base);

// Eq. (29), one feature block: (D, theta) -> (D', theta') for wheel travel (d_R, d_L).
// J_out_x is A^i of eq. (32), J_out_u is B^i (columns d_R, d_L).
Vec2 propagate_feature(const Vec2& x, double d_right, double d_left, double wheel_base,
                       Mat2* J_out_x = nullptr, Mat2* J_out_u = nullptr);

// The same block in inverse distance (q = 1/D, theta): the chain rule around eq. (29).
Vec2 propagate_feature_inverse(const Vec2& x, double d_right, double d_left, double wheel_base,
                               Mat2* J_out_x = nullptr, Mat2* J_out_u = nullptr);

// Eq. (27)/(30): predicted bearing of a feature (D, theta) seen by a camera with extrinsics
// ex, wrapped to (-pi, pi]. J_beta_x = [H1, H2, H3, H4, -1] of appendix A.4, i.e. the
// derivatives with respect to (D, theta, phi, rho, psi).
double predict_bearing(double D, double theta, const Extrinsics& ex, Row5* J_beta_x = nullptr);

// Eq. (27) with the feature in inverse distance (q, theta); J w.r.t. (q, theta, phi, rho, psi).
double predict_bearing_inverse(double q, double theta, const Extrinsics& ex,
                               Row5* J_beta_x = nullptr);

// The same bearing from plain geometry: the robot at pose (x_R, y_R, theta_R), a feature at
// world point f: beta = atan2(y_f - y_C, x_f - x_C) - (theta_R + phi + psi) (NOTES Sec. 1).
double bearing_from_geometry(const Eigen::Vector3d& robot_pose, const Vec2& feature,
                             const Extrinsics& ex);

// Eq. (31): covariance of the wheel travels (d_R, d_L): diag(K |d_R|, K |d_L|) + floor.
Mat2 chong_kleeman_covariance(double d_right, double d_left, double K, double floor);

// Feature initialisation from one bearing: the camera ray beta with the inverse distance
// q_c along it (from the camera centre). Returns (q = 1/D, theta) of the robot-centric
// state. J_out_in w.r.t. (q_c, beta) and J_out_ex w.r.t. (phi, rho, psi).
Vec2 feature_from_ray(double q_c, double beta, const Extrinsics& ex, Mat2* J_out_in = nullptr,
                      Mat23* J_out_ex = nullptr);

// World position of a feature (D, theta) seen from robot pose (x_R, y_R, theta_R), and the
// inverse map.
Vec2 feature_to_world(const Eigen::Vector3d& robot_pose, double D, double theta);
Vec2 feature_from_world(const Eigen::Vector3d& robot_pose, const Vec2& feature);

}  // namespace omnivert::calib
