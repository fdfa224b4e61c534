#include "omnivert/calib/robot_formats.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/file_io.hpp"

namespace omnivert::calib {

namespace {

// A number for the files: 10 significant digits, rounding noise below 1e-12 as 0, never "-0"
// (the inputs are finite: the pipeline refuses a non-finite estimate).
std::string num(double v) {
  if (std::abs(v) < 1e-12) v = 0.0;
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string row(const Eigen::Matrix4d& T, int i) {
  std::string s = "[";
  for (int j = 0; j < 4; ++j) s += (j ? ", " : "") + num(T(i, j));
  return s + "]";
}

// The comment lines every file starts with (after the comment marker `mark`).
std::string header(const std::string& mark, const MountingTransform& m, const RobotFrames& f) {
  std::string s;
  auto line = [&](const std::string& text) { s += mark + text + "\n"; };
  line("Camera mounting estimated by omnivert calibrate (docs/outputs.md#robot-formats).");
  line("Parent (base) frame: " + f.base + "; child (camera) frame: " + f.camera + ".");
  line("Direction: the pose of " + f.camera + " in " + f.base + ", i.e. T_" + "base_cam, which");
  line("maps a point from camera coordinates into base coordinates: p_base = T_base_cam p_cam.");
  line("Camera frame: x at bearing 0, z up along the mirror axis (not an optical frame).");
  line("Estimated: x, y, yaw. Not estimated: roll = pitch = 0 (mirror axis assumed vertical),");
  if (m.height_given)
    line("z = " + num(m.xyz(2)) + " m (the camera height given to calibrate, not estimated).");
  else
    line("z = 0 (the camera height is not estimated; put the measured one here).");
  return s;
}

}  // namespace

bool RobotFrames::IsValid(std::string* why) const {
  for (const std::string* name : {&base, &camera}) {
    if (name->empty()) {
      if (why) *why = "a frame name is empty";
      return false;
    }
    for (char c : *name)
      if (std::isspace(static_cast<unsigned char>(c)) || c == '"' || c == '\'' || c == '<' ||
          c == '>' || c == '&' || c == '`' || c == '$' || c == '\\') {
        if (why) *why = "frame name '" + *name + "' has a space, quote or <>&`$\\ character";
        return false;
      }
  }
  if (base == camera) {
    if (why) *why = "the base and camera frames have the same name '" + base + "'";
    return false;
  }
  if (camera_height && !std::isfinite(*camera_height)) {
    if (why) *why = "the camera height is not a finite number";
    return false;
  }
  return true;
}

MountingTransform mounting_transform(const Extrinsics& e,
                                     const Eigen::Matrix3d& C,
                                     const RobotFrames& frames) {
  MountingTransform m;
  const Eigen::Vector2d p = e.position();  // rho (cos phi, sin phi), Fig. 19
  m.height_given = frames.camera_height.has_value();
  m.xyz = {p(0), p(1), frames.camera_height.value_or(0.0)};
  m.rpy = {0.0, 0.0, e.yaw()};  // phi + psi, wrapped
  m.T_base_cam = e.T_base_cam();
  m.T_base_cam(2, 3) = m.xyz(2);
  // d(x, y, yaw) / d(phi, rho, psi); REP-103 indices of x, y, yaw: 0, 1, 5.
  Eigen::Matrix3d J;
  J << -e.rho * std::sin(e.phi), std::cos(e.phi), 0.0,  //
      e.rho * std::cos(e.phi), std::sin(e.phi), 0.0,    //
      1.0, 0.0, 1.0;
  const Eigen::Matrix3d Cxy = J * C * J.transpose();
  const int idx[3] = {0, 1, 5};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m.covariance(idx[i], idx[j]) = Cxy(i, j);
  return m;
}

std::string urdf_joint(const MountingTransform& m, const RobotFrames& f) {
  std::string s = "<!--\n" + header("  ", m, f) +
                  "  Paste the joint into the robot's URDF (or xacro) inside <robot>.\n-->\n";
  s += "<joint name=\"" + f.base + "_to_" + f.camera + "\" type=\"fixed\">\n";
  s += "  <parent link=\"" + f.base + "\"/>\n";
  s += "  <child link=\"" + f.camera + "\"/>\n";
  s += "  <origin xyz=\"" + num(m.xyz(0)) + " " + num(m.xyz(1)) + " " + num(m.xyz(2)) +
       "\" rpy=\"" + num(m.rpy(0)) + " " + num(m.rpy(1)) + " " + num(m.rpy(2)) + "\"/>\n";
  s += "</joint>\n";
  return s;
}

std::string static_transform_commands(const MountingTransform& m, const RobotFrames& f) {
  const std::string xyz = num(m.xyz(0)) + " " + num(m.xyz(1)) + " " + num(m.xyz(2));
  // ROS 1 takes the angles as yaw pitch roll (this order), ROS 2 names them.
  const std::string ypr = num(m.rpy(2)) + " " + num(m.rpy(1)) + " " + num(m.rpy(0));
  std::string s = header("# ", m, f);
  s += "# Copy ONE of the command lines below into a terminal or a launch file (each publishes\n"
       "# the same transform; units m and rad); do not run this file as a whole.\n";
  s += "\n# ROS 1, tf (x y z yaw pitch roll frame_id child_frame_id period_ms):\n";
  s += "rosrun tf static_transform_publisher " + xyz + " " + ypr + " " + f.base + " " + f.camera +
       " 100\n";
  s += "\n# ROS 1, tf2_ros (x y z yaw pitch roll frame_id child_frame_id):\n";
  s += "rosrun tf2_ros static_transform_publisher " + xyz + " " + ypr + " " + f.base + " " +
       f.camera + "\n";
  s += "\n# ROS 2 (Humble and later):\n";
  s += "ros2 run tf2_ros static_transform_publisher --x " + num(m.xyz(0)) + " --y " +
       num(m.xyz(1)) + " --z " + num(m.xyz(2)) + " --yaw " + num(m.rpy(2)) + " --pitch " +
       num(m.rpy(1)) + " --roll " + num(m.rpy(0)) + " --frame-id " + f.base + " --child-frame-id " +
       f.camera + "\n";
  return s;
}

std::string kalibr_yaml(const MountingTransform& m, const RobotFrames& f) {
  std::string s = header("# ", m, f);
  s += "# T_cam_base is its inverse: p_cam = T_cam_base p_base.\n";
  s += "base_frame: " + f.base + "\ncamera_frame: " + f.camera + "\n";
  s += "T_base_cam:\n";
  for (int i = 0; i < 4; ++i) s += "  - " + row(m.T_base_cam, i) + "\n";
  Eigen::Matrix4d inv = Eigen::Matrix4d::Identity();
  inv.block<3, 3>(0, 0) = m.T_base_cam.block<3, 3>(0, 0).transpose();
  inv.block<3, 1>(0, 3) = -inv.block<3, 3>(0, 0) * m.T_base_cam.block<3, 1>(0, 3);
  s += "T_cam_base:\n";
  for (int i = 0; i < 4; ++i) s += "  - " + row(inv, i) + "\n";
  s += "xyz: [" + num(m.xyz(0)) + ", " + num(m.xyz(1)) + ", " + num(m.xyz(2)) + "]\n";
  s += "rpy: [" + num(m.rpy(0)) + ", " + num(m.rpy(1)) + ", " + num(m.rpy(2)) + "]\n";
  s += "quaternion_xyzw: [0, 0, " + num(std::sin(0.5 * m.rpy(2))) + ", " +
       num(std::cos(0.5 * m.rpy(2))) + "]\n";
  s += "# Covariance of (x, y, z, roll, pitch, yaw) [m, rad], REP-103 order, row-major: the\n"
       "# (phi, rho, psi) covariance propagated to first order; the rows and columns of the\n"
       "# dimensions not estimated are 0 (not: known exactly).\n";
  s += "covariance_order: [x, y, z, roll, pitch, yaw]\n";
  static const char* names[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  s += "estimated: {";
  for (int i = 0; i < 6; ++i)
    s += std::string(i ? ", " : "") + names[i] + ": " + (m.estimated[i] ? "true" : "false");
  s += "}\nsigma: {";
  for (int i = 0; i < 6; ++i)
    s += std::string(i ? ", " : "") + names[i] + ": " +
         num(std::sqrt(std::max(m.covariance(i, i), 0.0)));
  s += "}\ncovariance:\n";
  for (int i = 0; i < 6; ++i) {
    s += "  - [";
    for (int j = 0; j < 6; ++j) s += (j ? ", " : "") + num(m.covariance(i, j));
    s += "]\n";
  }
  return s;
}

void write_robot_formats(const std::string& dir,
                         const Extrinsics& e,
                         const Eigen::Matrix3d& C,
                         const RobotFrames& frames) {
  const MountingTransform m = mounting_transform(e, C, frames);
  const std::filesystem::path d(dir);
  write_text_atomic((d / kRobotFormatFiles[0]).string(), urdf_joint(m, frames));
  write_text_atomic((d / kRobotFormatFiles[1]).string(), static_transform_commands(m, frames));
  write_text_atomic((d / kRobotFormatFiles[2]).string(), kalibr_yaml(m, frames));
}

}  // namespace omnivert::calib
