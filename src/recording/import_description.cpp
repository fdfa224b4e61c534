// The robot's description in a recording, used by the import (import_steps.hpp): the wheel
// base and radius of /robot_description, the camera's mount of /tf_static.

#include <cmath>
#include <cstdio>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "recording/import_steps.hpp"

namespace omnivert::recording {

namespace {

std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// The wheel base and radius of the URDF, for those not given.
void use_urdf(const Recording& rec, const Collected& c, ImportOptions& o, ImportSummary& s) {
  const bool need_base = !(o.wheel_base > 0);
  const bool need_radius = !o.joint_states_topic.empty() && !(o.wheel_radius > 0);
  if (!need_base && !need_radius) return;
  if (c.robot_description.empty() || o.left_joint.empty() || o.right_joint.empty()) return;
  const std::string what = rec.path() + ", topic " + kRobotDescriptionTopic;
  const Urdf urdf = parse_urdf(c.robot_description, what);
  const UrdfWheels w = urdf_wheels(urdf, o.left_joint, o.right_joint, what);
  if (need_base) {
    o.wheel_base = w.wheel_base;
    s.wheel_base_from_description = true;
  }
  if (need_radius && w.wheel_radius) {
    o.wheel_radius = *w.wheel_radius;
    s.wheel_radius_from_description = true;
  }
}

// The mount: base_frame -> camera_frame composed from the static transforms.
void use_tf_static(const Recording& rec,
                   const Collected& c,
                   const ImportOptions& o,
                   ImportSummary& s) {
  s.base_frame = o.base_frame;
  s.camera_frame = !o.camera_frame.empty() ? o.camera_frame : c.camera_frame_id;
  if (c.tf_static.empty()) {
    s.mount_source = "the recording has no " + std::string(kTfStaticTopic);
    return;
  }
  if (s.camera_frame.empty()) {
    s.mount_source = "the images have no header.frame_id: give the camera's frame";
    return;
  }
  FrameTree tree;
  for (const TransformMsg& m : c.tf_static) {
    const Eigen::Quaterniond q(m.rotation[3], m.rotation[0], m.rotation[1], m.rotation[2]);
    FrameTransform t{m.parent, m.child, Eigen::Isometry3d::Identity()};
    if (!(q.norm() > 0.5)) continue;  // an unset rotation: not a transform
    t.T_parent_child.linear() = q.normalized().toRotationMatrix();
    t.T_parent_child.translation() =
        Eigen::Vector3d(m.translation[0], m.translation[1], m.translation[2]);
    tree.add(t);
  }
  std::string why;
  const auto T = tree.transform(s.base_frame, s.camera_frame, &why);
  const std::string where = std::string(kTfStaticTopic) + " of " + rec.path();
  if (!T) {
    s.mount_source =
        where + " has no transform " + s.base_frame + " -> " + s.camera_frame + ": " + why;
    s.warnings.push_back(s.mount_source + "; the prior is calibrate's default or its flags");
    return;
  }
  s.mount = camera_mount(*T);
  s.mount_source = where + " (" + s.base_frame + " -> " + s.camera_frame + ")";
  if (s.mount->tilt > deg2rad(10.0)) {
    char buf[200];
    std::snprintf(buf,
                  sizeof buf,
                  "; its z axis is %.1f deg from the base's: omnivert's camera frame has z up the "
                  "mirror axis (an optical frame, z forward, is not one), check the camera frame",
                  rad2deg(s.mount->tilt));
    s.warnings.push_back("the camera's mount in " + s.mount_source + buf);
  }
}

}  // namespace

void use_description(const Recording& rec, const Collected& c, ImportOptions& o, ImportSummary& s) {
  use_urdf(rec, c, o, s);
  use_tf_static(rec, c, o, s);
}

std::string prior_yaml(const ImportSummary& s) {
  const CameraMount& m = *s.mount;
  std::string y = "# omnivert import: the camera's mount from " + s.mount_source + "\n";
  y += "# phi, rho, psi of docs/theory/conventions.md; calibrate takes them as its prior\n";
  y += "source: \"" + s.mount_source + "\"\n";
  y += "base_frame: " + s.base_frame + "\n";
  y += "camera_frame: " + s.camera_frame + "\n";
  y += "phi: " + number(m.phi) + "  # rad\n";
  y += "rho: " + number(m.rho) + "  # m\n";
  y += "psi: " + number(m.psi) + "  # rad\n";
  y += "camera_height: " + number(m.height) + "  # m, z of the camera centre in the base frame\n";
  y += "tilt: " + number(m.tilt) + "  # rad, the camera z axis from the base's\n";
  return y;
}

}  // namespace omnivert::recording
