#pragma once
// Odometry given as poses (nav_msgs/Odometry, a TUM pose file) turned into the wheel travel
// of wheel0/data.csv, so that the filter, the Chong-Kleeman noise and the wheel checks apply
// unchanged (docs/dataset-format.md#odometry-from-poses).

#include <span>
#include <string>
#include <vector>

#include "omnivert/dataset/dataset.hpp"

namespace omnivert::dataset {

struct PosesToWheelsOptions {
  double wheel_base = 0;  // e [m], eq. (15)
  // A step faster than this is refused as a jump of the odometry [m/s].
  double max_speed = 5.0;
  // What the poses are, for messages ("run.bag, topic /odom").
  std::string source;
};

// Cumulative left/right wheel travel [m] at each pose (the first is 0, 0). Each planar step
// (dx, dy, dtheta) is inverted through eqs. (14)-(15) for a differential drive moving along a
// circular arc (constant wheel speeds between two poses): dtheta = theta' - theta (wrapped),
// the chord points along theta + dtheta/2 (eq. 14), the arc length is
// s = chord * (dtheta/2) / sin(dtheta/2), and eq. (15) gives
// right = s + e dtheta / 2, left = s - e dtheta / 2. Exact for an arc; motion sideways to the
// chord (which a differential drive cannot make) is dropped.
//
// Throws InputError naming options.source, the pose index and its time for: timestamps that do
// not increase, an odometry reset (a jump back to the zero pose, x = y = theta = 0, from a pose
// away from it), and any other step faster than options.max_speed.
std::vector<WheelRecord> wheel_travel_from_poses(std::span<const PoseRecord> poses,
                                                 const PosesToWheelsOptions& options);

// The yaw (rotation about z) of a unit quaternion (x, y, z, w) [rad].
double yaw_of_quaternion(double qx, double qy, double qz, double qw);

// A TUM-style pose file: one pose a line, "t x y z qx qy qz qw" separated by spaces or commas,
// t in seconds; lines starting with '#' and blank lines are skipped. Throws InputError naming
// the file and the line for a line that does not parse.
std::vector<PoseRecord> read_tum_poses(const std::string& path);

}  // namespace omnivert::dataset
