#pragma once
// The motion and observation models of the self-calibration filter (paper Sec. 7, 8.2 and
// appendix A.4), one feature at a time. Jacobians are optional out-parameters named
// J_out_in (d out / d in), computed only when asked for.
//
// Feature state (eq. 19): D = distance from the robot origin to the feature,
// theta = theta_R - atan2(y_R - y_f, x_R - x_f). In the robot frame the feature is at
// (-D cos theta, D sin theta).

#include <Eigen/Core>
#include <functional>
#include <set>
#include <utility>
#include <vector>

#include "omnivert/calib/options.hpp"

namespace omnivert::calib {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;
using Row5 = Eigen::Matrix<double, 1, 5>;
using Mat23 = Eigen::Matrix<double, 2, 3>;

// Eq. (15): d_rho = (d_R + d_L) / 2, d_theta = (d_R - d_L) / e. Returns (d_rho, d_theta).
Vec2 wheel_step(double d_right, double d_left, double wheel_base, Mat2* J_step_wheels = nullptr);

// Eq. (14) over many wheel samples between two images: `travel` holds the cumulative
// (left, right) wheel travel at the first image, at each wheel sample between, and at the
// second image; each sample-to-sample step is integrated by eq. (14) and the composed motion
// is returned as one step of eq. (14) plus a sideways displacement: (d_right, d_left,
// lateral) with d_theta = (d_right - d_left) / e the total turn and the displacement
// (d_right + d_left) / 2 along, `lateral` across, the mid-step heading (FrameInput). Exact
// where the wheels change speed within the frame (a straight that ends in a turn), which
// one step of eq. (14) over the frame is not.
// With `covariance_per_K`, the covariance of the result per unit K when each sample step of
// each wheel has the noise of eq. (31), variance K |d| (first order).
Eigen::Vector3d compose_wheel_steps(const std::vector<Eigen::Vector2d>& travel,
                                    double wheel_base,
                                    Eigen::Matrix3d* covariance_per_K = nullptr);

// Eq. (14) with the sideways displacement of compose_wheel_steps (FrameInput::lateral).
Eigen::Vector3d integrate_pose_lateral(
    const Eigen::Vector3d& pose, double d_right, double d_left, double lateral, double wheel_base);

// Eq. (14): pose (x, y, theta) after one odometry step (midpoint heading).
Eigen::Vector3d integrate_pose(const Eigen::Vector3d& pose,
                               double d_right,
                               double d_left,
                               double wheel_base);

// Eq. (29), one feature block: (D, theta) -> (D', theta') for wheel travel (d_R, d_L).
// J_out_x is A^i of eq. (32), J_out_u is B^i (columns d_R, d_L).
Vec2 propagate_feature(const Vec2& x,
                       double d_right,
                       double d_left,
                       double wheel_base,
                       Mat2* J_out_x = nullptr,
                       Mat2* J_out_u = nullptr);

// The same block in inverse distance (q = 1/D, theta): the chain rule around eq. (29).
Vec2 propagate_feature_inverse(const Vec2& x,
                               double d_right,
                               double d_left,
                               double wheel_base,
                               Mat2* J_out_x = nullptr,
                               Mat2* J_out_u = nullptr);

// Eq. (27)/(30): predicted bearing of a feature (D, theta) seen by a camera with extrinsics
// ex, wrapped to (-pi, pi]. J_beta_x = [H1, H2, H3, H4, -1] of appendix A.4, i.e. the
// derivatives with respect to (D, theta, phi, rho, psi).
double predict_bearing(double D, double theta, const Extrinsics& ex, Row5* J_beta_x = nullptr);

// Eq. (27) with the feature in inverse distance (q, theta); J w.r.t. (q, theta, phi, rho, psi).
double predict_bearing_inverse(double q,
                               double theta,
                               const Extrinsics& ex,
                               Row5* J_beta_x = nullptr);

// The same bearing from plain geometry: the robot at pose (x_R, y_R, theta_R), a feature at
// world point f: beta = atan2(y_f - y_C, x_f - x_C) - (theta_R + phi + psi)
// (docs/theory/conventions.md).
double bearing_from_geometry(const Eigen::Vector3d& robot_pose,
                             const Vec2& feature,
                             const Extrinsics& ex);

// Eq. (31): covariance of the wheel travels (d_R, d_L): diag(K |d_R|, K |d_L|) + floor.
Mat2 chong_kleeman_covariance(double d_right, double d_left, double K, double floor);

// Feature initialisation from one bearing: the camera ray beta with the inverse distance
// q_c along it (from the camera centre). Returns (q = 1/D, theta) of the robot-centric
// state. J_out_in w.r.t. (q_c, beta) and J_out_ex w.r.t. (phi, rho, psi).
Vec2 feature_from_ray(double q_c,
                      double beta,
                      const Extrinsics& ex,
                      Mat2* J_out_in = nullptr,
                      Mat23* J_out_ex = nullptr);

// World position of a feature (D, theta) seen from robot pose (x_R, y_R, theta_R), and the
// inverse map.
Vec2 feature_to_world(const Eigen::Vector3d& robot_pose, double D, double theta);
Vec2 feature_from_world(const Eigen::Vector3d& robot_pose, const Vec2& feature);

// ---------------------------------------------------------------------------------------
// The invariant parametrisation (FeatureInit::kAnchoredInverseDepth). Features are points of
// the robot frame, p = (p_x, p_y) (the same point as (D, theta): p = (-D cos theta,
// D sin theta)), or, while their depth is poorly known, anchored inverse-depth points
// (a_x, a_y, alpha, q): the point a + (cos alpha, sin alpha) / q, with the anchor a = the
// camera centre when the track started, carried along in the robot frame. The extrinsics are
// the camera position c = rho (cos phi, sin phi) and yaw eta = phi + psi. In these coordinates
// the direction that straight motion cannot observe (move the camera and every feature by
// the same vector, Sec. 8.1) is a constant vector, so the EKF's linearisation at changing
// estimates cannot create information along it (the "first-estimates" inconsistency of
// Huang, Mourikis and Roumeliotis 2008, measured in the paper's (D, theta) coordinates).

using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat42 = Eigen::Matrix<double, 4, 2>;
using Row3 = Eigen::Matrix<double, 1, 3>;
using Row4 = Eigen::Matrix<double, 1, 4>;

// Eq. (14) seen from the robot: a world point's robot-frame coordinates after one odometry
// step, p' = R(-d_theta) (p - d_rho (cos(d_theta / 2), sin(d_theta / 2))).
// J_out_u columns (d_R, d_L).
Vec2 propagate_point(const Vec2& p,
                     double d_right,
                     double d_left,
                     double wheel_base,
                     Mat2* J_out_p = nullptr,
                     Mat2* J_out_u = nullptr);

// Anchored inverse-depth point (a_x, a_y, alpha, q): the anchor moves as a point, alpha
// turns with the robot (alpha' = alpha - d_theta), q is unchanged.
Vec4 propagate_anchored(const Vec4& f,
                        double d_right,
                        double d_left,
                        double wheel_base,
                        Mat4* J_out_f = nullptr,
                        Mat42* J_out_u = nullptr);

// Bearing of robot-frame point p from a camera at c with yaw eta: atan2(p - c) - eta
// (eq. 16-17 in the robot frame). J_beta_p (1x2), J_beta_cam w.r.t. (c_x, c_y, eta).
double predict_bearing_point(const Vec2& p,
                             const Vec3& cam,
                             Eigen::Matrix<double, 1, 2>* J_beta_p = nullptr,
                             Row3* J_beta_cam = nullptr);

// Bearing of an anchored inverse-depth point: atan2(q (a - c) + (cos alpha, sin alpha)) - eta
// (the direction of p - c scaled by q > 0, defined for q -> 0).
double predict_bearing_anchored(const Vec4& f,
                                const Vec3& cam,
                                Row4* J_beta_f = nullptr,
                                Row3* J_beta_cam = nullptr);

// Anchored inverse-depth point -> robot-frame point, p = a + (cos alpha, sin alpha) / q.
Vec2 anchored_to_point(const Vec4& f, Eigen::Matrix<double, 2, 4>* J_p_f = nullptr);

// Robot-frame point <-> (D, theta) of eq. (19).
Vec2 point_to_distance_form(const Vec2& p, Mat2* J_out_p = nullptr);

// Camera pose (c_x, c_y, eta) <-> extrinsics (phi, rho, psi).
Vec3 camera_pose_from_extrinsics(const Extrinsics& ex, Mat3* J_cam_ex = nullptr);
Extrinsics extrinsics_from_camera_pose(const Vec3& cam, Mat3* J_ex_cam = nullptr);

// The crossing guard's test (CalibrationOptions::association.crossing_guard): of directions (angle
// [rad], key), the keys with another direction within `guard` of theirs on the circle; a pair for
// which same_line(key_a, key_b) is true does not count (two parts of one split track).
std::set<int> crowded_directions(std::vector<std::pair<double, int>> directions,
                                 double guard,
                                 const std::function<bool(int, int)>& same_line = {});

}  // namespace omnivert::calib
