#pragma once
// A top view of a simulation, for people to look at: walls (grey, darker for partial
// height), vertical edges (dots, red for partial height), the robot's path (blue) with its
// start (green) and the camera centre's path (orange). Written as ground_truth/map.png.

#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/sim/trajectory.hpp"
#include "omnivert/sim/world.hpp"

namespace omnivert::sim {

// robot: robot poses (x, y, theta); camera: camera centres (x, y). The picture is at most
// max_size pixels wide or high, with north (+y) up.
cv::Mat3b draw_map(const World& world,
                   const std::vector<Pose2>& robot,
                   const std::vector<Eigen::Vector2d>& camera,
                   int max_size = 1000);

}  // namespace omnivert::sim
