#pragma once
// The estimate in the formats a robot's software takes (docs/outputs.md#robot-formats): a URDF
// fixed joint, static_transform_publisher command lines for ROS 1 and ROS 2, and a
// Kalibr-style YAML with T_base_cam, T_cam_base and the covariance in REP-103 order.
//
// Direction (docs/theory/conventions.md#extrinsics-and-t_base_cam): every file gives the pose
// of the camera frame in the base frame, T_base_cam = [Rz(phi + psi) | (rho cos phi,
// rho sin phi, z)], which maps a point from camera coordinates into base coordinates,
// p_base = T_base_cam p_cam. That is a URDF joint's <origin> (parent base, child camera) and
// the transform static_transform_publisher publishes from frame_id (base) to child_frame_id
// (camera). The camera frame is omnivert's: x at bearing 0, z up along the mirror axis (not
// an optical frame with z forward).
//
// Only x, y and yaw are estimated (the bearings are 2-D, paper Sec. 7): the height z is the
// caller's (0 when not given), roll and pitch are 0 (the mirror axis is assumed vertical);
// their covariance rows and columns are zero and each file says they are not estimated.

#include <array>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

struct RobotFrames {
  std::string base = "base_link";      // the robot's frame (REP-105 base_link)
  std::string camera = "camera_link";  // the camera's frame
  // The camera centre's height above the base frame's origin [m]: not estimated by this
  // method; empty: 0 in the files, which say so.
  std::optional<double> camera_height;

  // Frame names are non-empty, without spaces, quotes or '<', '>', '&' (they go into XML,
  // YAML and a shell line unquoted); a height, when given, is finite.
  bool IsValid(std::string* why) const;
};

// The mounting in REP-103 terms.
struct MountingTransform {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  // camera centre in the base frame [m]
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();  // roll, pitch, yaw [rad], R = Rz Ry Rx
  Eigen::Matrix4d T_base_cam = Eigen::Matrix4d::Identity();
  // Covariance of (x, y, z, roll, pitch, yaw) [m, rad], REP-103 order: the first-order
  // propagation of the (phi, rho, psi) covariance through x = rho cos phi, y = rho sin phi,
  // yaw = phi + psi; the rows and columns of z, roll and pitch are zero.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  std::array<bool, 6> estimated{true, true, false, false, false, true};
  bool height_given = false;  // z is the caller's camera_height
};

// The mounting of `e` with covariance `C` over (phi, rho, psi).
MountingTransform mounting_transform(const Extrinsics& e,
                                     const Eigen::Matrix3d& C,
                                     const RobotFrames& frames = {});

// The files' texts, each starting with comments naming the frames and the direction.
// camera_joint.urdf: a <joint type="fixed"> with <origin xyz rpy>.
std::string urdf_joint(const MountingTransform& m, const RobotFrames& frames);
// static_transform_publisher.sh: the ROS 1 tf and tf2_ros lines and the ROS 2 line.
std::string static_transform_commands(const MountingTransform& m, const RobotFrames& frames);
// extrinsics_kalibr.yaml: frames, T_base_cam, T_cam_base, xyz, rpy, quaternion, sigmas and
// the 6x6 covariance in REP-103 order, which dimensions are estimated.
std::string kalibr_yaml(const MountingTransform& m, const RobotFrames& frames);

// The three files' names, in the order above.
inline constexpr const char* kRobotFormatFiles[] = {
    "camera_joint.urdf", "static_transform_publisher.sh", "extrinsics_kalibr.yaml"};

// Writes the three files into `dir` (each atomically).
void write_robot_formats(const std::string& dir,
                         const Extrinsics& e,
                         const Eigen::Matrix3d& C,
                         const RobotFrames& frames = {});

}  // namespace omnivert::calib
