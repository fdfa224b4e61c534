#pragma once
// The simulator: drives a robot with a catadioptric camera through a world and writes a
// dataset in the layout every omnivert tool reads (docs/simulator.md, dataset/dataset.hpp):
//
//   cam0/data.csv, cam0/data/<timestamp>.png, cam0/sensor.yaml (cam0/mask.png when asked)
//   laser0/data.csv, laser0/sensor.yaml (when SimConfig::laser.enabled)
//   wheel0/data.csv, wheel0/sensor.yaml
//   ground_truth/extrinsics.yaml, poses.csv, lines.csv, edges.csv, world.yaml,
//   ground_truth/simulation.yaml (every setting used, for reproduction)
//
// The dataset is written into a temporary sibling directory and renamed into place when
// complete, so an interrupted run never leaves a dataset that looks complete.

#include <cstdint>
#include <functional>
#include <string>

#include "omnivert/sim/camera_model.hpp"
#include "omnivert/sim/laser.hpp"
#include "omnivert/sim/renderer.hpp"
#include "omnivert/sim/robot_overlay.hpp"
#include "omnivert/sim/sensors.hpp"
#include "omnivert/sim/trajectory.hpp"
#include "omnivert/sim/world.hpp"

namespace omnivert::sim {

// Camera-to-odometry extrinsics (docs/theory/conventions.md, Fig. 19): camera centre at
// rho (cos phi, sin phi) in the robot frame, camera x-axis at phi + psi from the robot x-axis.
// Defaults: the paper's estimates (Sec. 9.2).
struct Extrinsics {
  double phi = -0.34;
  double rho = 0.23;
  double psi = 0.33;
};

struct SimConfig {
  std::uint64_t seed = 1;
  int max_frames = 0;                                 // 0: the whole trajectory
  double frame_rate = 3.0;                            // [Hz], Sec. 9
  double camera_height = 0.9;                         // camera centre above the floor [m]
  std::int64_t start_ns = 1'600'000'000'000'000'000;  // timestamp of the motion's start
  CatadioptricCamera camera;
  Extrinsics extrinsics;
  WheelConfig wheel;
  ImageSensor image;
  RobotOverlay overlay;        // struts and the robot's reflection in the image; none by default
  LaserConfig laser;           // a 2D laser scanner (laser0/); off by default
  double min_clearance = 0.2;  // the robot centre keeps this far from every wall [m]
  double min_line_px = 2.0;    // ground-truth lines shorter than this (radially) are left out
  int people = 0;              // people walking through the scene (sim/people.hpp), from the seed
};

// The camera pose for a robot pose (docs/theory/conventions.md).
CameraPose camera_pose(const Pose2& robot, const Extrinsics& x, double camera_height);

// Empty if the robot centre keeps `clearance` from every wall over [0, t_end] (sampled every
// 20 ms); else where and which wall it comes too close to.
std::string free_space_violation(const World& world,
                                 const std::vector<MotionPiece>& motion,
                                 double t_end,
                                 double clearance);

struct SimSummary {
  int frames = 0;
  int wheel_samples = 0;
  double distance = 0;    // robot centre path length [m]
  double mean_lines = 0;  // visible ground-truth lines per frame
  double seconds = 0;     // wall-clock time
};

// Simulates and writes the dataset to out_dir. Throws InputError when out_dir exists (and
// overwrite is false), when the trajectory leaves the free space of the world, or when a
// setting is invalid. `progress(done, total)` is called after every frame when given.
SimSummary simulate(const World& world,
                    const Trajectory& trajectory,
                    const SimConfig& config,
                    const std::string& out_dir,
                    bool overwrite = false,
                    const std::function<void(int, int)>& progress = {});

}  // namespace omnivert::sim
