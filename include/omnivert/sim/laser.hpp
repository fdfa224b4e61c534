#pragma once
// The simulated 2D laser scanner (docs/simulator.md#laser-scanner): a scan plane at a given
// height, rays cast against the world's walls that span that height (boxes, pillars and
// walls; a panel or a strip is paint, invisible to it), Gaussian range noise and a maximum
// range (no return beyond: inf, as REP 117 of ROS has it). The scans are written as laser0/ of
// the dataset (dataset/laser.hpp), the reference of the check of paper Sec. 9.2 (Figs. 23, 26).

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "omnivert/sim/trajectory.hpp"
#include "omnivert/sim/world.hpp"

namespace omnivert::sim {

struct LaserConfig {
  bool enabled = false;  // write laser0/
  double rate_hz = 10.0;
  // The scanner's pose on the robot: (x, y) [m], yaw [rad] in the robot frame, and the height
  // of its scan plane above the floor [m].
  double x = 0.15, y = 0.0, yaw = 0.0, height = 0.3;
  double angle_min = -3.14159265358979323846;  // [rad]
  double angle_increment = 0.25 * 3.14159265358979323846 / 180.0;
  int rays = 1440;                           // 360 degrees at 0.25 degree
  double range_min = 0.05, range_max = 8.0;  // [m]
  double noise_sigma = 0.005;                // [m]
  // Empty if the settings are usable; else what is wrong.
  std::string validate() const;
};

// The ranges [m] of one scan from the robot pose `robot` (inf: no wall within range_max).
std::vector<float> laser_ranges(const World& world,
                                const Pose2& robot,
                                const LaserConfig& config,
                                std::mt19937_64& rng);

// Writes laser0/data.csv and laser0/sensor.yaml under `dataset_dir`: scans every 1/rate_hz
// from t = 0 to t_end [s] of the motion, stamped start_ns + t.
void write_laser(const std::string& dataset_dir,
                 const World& world,
                 const std::vector<MotionPiece>& motion,
                 double t_end,
                 const LaserConfig& config,
                 std::int64_t start_ns,
                 std::mt19937_64& rng);

}  // namespace omnivert::sim
