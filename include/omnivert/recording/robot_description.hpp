#pragma once
// The robot's own description in a recording (docs/import.md#the-robots-description): the static
// transforms of /tf_static (tf2_msgs/TFMessage) and the URDF of /robot_description
// (std_msgs/String). From them: the camera's mount on the robot, as the calibration's prior
// (phi, rho, psi of docs/theory/conventions.md#extrinsics-and-t_base_cam), and the wheel base
// and wheel radius of a differential drive.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace omnivert::recording {

// A transform between two frames: the pose of `child` in `parent`, which maps child
// coordinates into the parent's (p_parent = T_parent_child p_child), as tf's TransformStamped
// (header.frame_id the parent, child_frame_id the child) and a URDF joint's <origin> give it.
struct FrameTransform {
  std::string parent, child;
  Eigen::Isometry3d T_parent_child = Eigen::Isometry3d::Identity();
};

// Frames as a tree, each child with one parent (tf and URDF require it); a later transform of
// the same child replaces the earlier one (a latched /tf_static republished).
class FrameTree {
 public:
  void add(const FrameTransform& t);
  bool empty() const { return parent_of_.empty(); }
  // T_from_to: maps coordinates of frame `to` into frame `from`, composed along the tree
  // through the two frames' nearest common ancestor. nullopt when they are not connected
  // (`why` says which is missing).
  std::optional<Eigen::Isometry3d> transform(const std::string& from,
                                             const std::string& to,
                                             std::string* why = nullptr) const;
  // The frames' names, sorted and comma-separated (for messages).
  std::string frames() const;

 private:
  // T_root_frame and the chain of frames from `frame` up to its root.
  std::vector<std::string> chain(const std::string& frame) const;
  std::map<std::string, FrameTransform> parent_of_;  // by child
};

// A URDF's joints as transforms (parent link -> child link, <origin xyz rpy>, R = Rz Ry Rx), the
// child link of each joint by the joint's name, and the radius of each link whose collision (or
// else visual) geometry is a cylinder. Throws InputError naming `what` when the XML does not
// parse or a joint lacks its parent or child.
struct Urdf {
  FrameTree tree;
  std::map<std::string, std::string> joint_child;
  std::map<std::string, double> cylinder_radius;
};
Urdf parse_urdf(const std::string& xml, const std::string& what);

// A differential drive's wheels in a URDF, by the names of the two wheel joints: the wheel base
// e of eq. (15) is the distance between the joints' origins (the wheel centres; the frame does
// not matter), the radius the wheel links' cylinders' (their mean; nullopt when neither is a
// cylinder). Throws InputError naming `what` when a joint is not in the URDF or the two are not
// connected.
struct UrdfWheels {
  double wheel_base = 0;
  std::optional<double> wheel_radius;
};
UrdfWheels urdf_wheels(const Urdf& urdf,
                       const std::string& left_joint,
                       const std::string& right_joint,
                       const std::string& what);

// The camera's mount in the paper's parameters (Fig. 19, conventions.md) from T_base_cam, the
// camera frame's pose in the base frame: the camera centre at rho (cos phi, sin phi), its x axis
// at phi + psi from the base's (the heading of the camera's x axis projected on the base's
// plane). rho = 0 gives phi = 0. `tilt` is the angle between the two z axes: near 0 for a
// camera frame of omnivert's convention (z up the mirror axis); an optical frame (z forward)
// gives 90 degrees.
struct CameraMount {
  double phi = 0, rho = 0, psi = 0;  // [rad, m, rad]
  double height = 0;                 // z of the camera centre in the base frame [m]
  double tilt = 0;                   // [rad]
};
CameraMount camera_mount(const Eigen::Isometry3d& T_base_cam);

}  // namespace omnivert::recording
