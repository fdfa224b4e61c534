#pragma once
// Readers of the robot-format files (calib/robot_formats.hpp) the way a robot's software reads
// them: the URDF <origin xyz rpy> (R = Rz(yaw) Ry(pitch) Rx(roll)), the static_transform_publisher
// lines (ROS 1: x y z yaw pitch roll parent child; ROS 2: named flags), the YAML's 4x4
// matrices. Independent of the writer's code: text in, matrix out.

#include <cmath>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace omnivert::testing {

struct ParsedTransform {
  Eigen::Matrix4d T = Eigen::Matrix4d::Constant(NAN);  // pose of child in parent
  std::string parent, child;
  bool found = false;
};

inline Eigen::Matrix4d transform_from_xyz_rpy(
    double x, double y, double z, double roll, double pitch, double yaw) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.block<3, 3>(0, 0) = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                            .toRotationMatrix();
  T.block<3, 1>(0, 3) = Eigen::Vector3d(x, y, z);
  return T;
}

inline std::vector<double> numbers_of(const std::string& text) {
  std::istringstream in(text);
  std::vector<double> v;
  for (double d; in >> d;) v.push_back(d);
  return v;
}

inline ParsedTransform parse_urdf_joint(const std::string& text) {
  ParsedTransform p;
  std::smatch m;
  const std::regex origin("<origin xyz=\"([^\"]*)\" rpy=\"([^\"]*)\"\\s*/>");
  const std::regex parent("<parent link=\"([^\"]*)\"\\s*/>"),
      child("<child link=\"([^\"]*)\"\\s*/>");
  if (!std::regex_search(text, m, origin)) return p;
  const auto xyz = numbers_of(m[1]), rpy = numbers_of(m[2]);
  if (xyz.size() != 3 || rpy.size() != 3) return p;
  p.T = transform_from_xyz_rpy(xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2]);
  if (std::regex_search(text, m, parent)) p.parent = m[1];
  if (std::regex_search(text, m, child)) p.child = m[1];
  p.found = true;
  return p;
}

// `prefix` "rosrun tf static_transform_publisher" or "rosrun tf2_ros static_transform_publisher":
// x y z yaw pitch roll frame_id child_frame_id [period_ms].
inline ParsedTransform parse_ros1_line(const std::string& text, const std::string& prefix) {
  ParsedTransform p;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(prefix + " ", 0) != 0) continue;
    std::istringstream t(line.substr(prefix.size()));
    double v[6];
    for (double& d : v) t >> d;
    t >> p.parent >> p.child;
    if (!t) return p;
    p.T = transform_from_xyz_rpy(v[0], v[1], v[2], v[5], v[4], v[3]);
    p.found = true;
    return p;
  }
  return p;
}

inline ParsedTransform parse_ros2_line(const std::string& text) {
  ParsedTransform p;
  std::smatch m;
  const std::regex line(
      "ros2 run tf2_ros static_transform_publisher --x (\\S+) --y (\\S+) --z (\\S+) --yaw (\\S+) "
      "--pitch (\\S+) --roll (\\S+) --frame-id (\\S+) --child-frame-id (\\S+)");
  if (!std::regex_search(text, m, line)) return p;
  p.T = transform_from_xyz_rpy(std::stod(m[1]),
                               std::stod(m[2]),
                               std::stod(m[3]),
                               std::stod(m[6]),
                               std::stod(m[5]),
                               std::stod(m[4]));
  p.parent = m[7];
  p.child = m[8];
  p.found = true;
  return p;
}

// The 4x4 matrix under `key:` (four lines "  - [a, b, c, d]").
inline Eigen::Matrix4d parse_yaml_matrix(const std::string& text, const std::string& key) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Constant(NAN);
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line) && line != key + ":") {
  }
  for (int i = 0; i < 4 && std::getline(in, line); ++i) {
    const std::size_t open = line.find('[');
    if (line.rfind("  - ", 0) != 0 || open == std::string::npos) break;
    std::string s = line.substr(open);
    for (char& c : s)
      if (c == '[' || c == ']' || c == ',') c = ' ';
    const auto v = numbers_of(s);
    if (v.size() != 4) return Eigen::Matrix4d::Constant(NAN);
    for (int j = 0; j < 4; ++j) T(i, j) = v[j];
  }
  return T;
}

}  // namespace omnivert::testing
