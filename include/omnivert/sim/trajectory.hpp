#pragma once
// Robot trajectories for the simulator: a differential-drive robot (Sec. 7, eq. 14-15) that
// drives a list of segments (straights, turns in place, arcs, waits) at constant wheel
// speeds per segment. Poses are exact (integrated in closed form), so ground truth is exact
// at any time.
//
// Presets (`trajectory_presets()`):
//   paper    2.3 m straight, then a 180 degree turn in place (Sec. 9.2), 3.8 cm per frame at 3 Hz
//   zigzag   alternating straights and turns, ending with a turn in place
//   straight 4 m straight only (degenerate for calibration, Sec. 8.1: rho is not observable)
//   tour     a 4 m x 1 m loop driven 9 times, about 90 m: >= 1800 frames at ~5 cm per frame
// A YAML file gives user-defined segments (docs/simulator.md).

#include <string>
#include <vector>

#include <Eigen/Core>

namespace omnivert::sim {

// Robot pose in the world: x, y [m], theta [rad].
using Pose2 = Eigen::Vector3d;

struct Segment {
  enum class Kind { kStraight, kTurn, kArc, kWait };
  Kind kind = Kind::kStraight;
  double distance = 0;  // straight: signed [m]; arc: signed arc length of the centre [m]
  double angle = 0;     // turn, arc: signed [rad], counter-clockwise positive
  double duration = 0;  // wait: [s]
};

// Robot velocities (v [m/s], omega [rad/s]) between t0 and t1 (a piece of a segment).
struct MotionPiece {
  double t0 = 0, t1 = 0;
  double v = 0, omega = 0;
  Pose2 start = Pose2::Zero();
};

struct Trajectory {
  std::string name = "trajectory";
  double speed = 0.114;    // [m/s] on straights and arcs (0.114: 3.8 cm per frame at 3 Hz)
  double turn_rate = 0.3;  // [rad/s] on turns in place
  bool has_start = false;  // start given by the trajectory (else the world's start pose)
  Pose2 start = Pose2::Zero();
  std::vector<Segment> segments;

  // The motion, as pieces of constant (v, omega), beginning at `start` at time 0.
  std::vector<MotionPiece> pieces(const Pose2& start_pose) const;
  std::string validate() const;
};

// Robot pose at time t [s] of a motion (t clamped to the motion's span). Exact: constant
// (v, omega) pieces integrate in closed form.
Pose2 pose_at(const std::vector<MotionPiece>& motion, double t);
// Robot velocities at time t (zero outside the motion).
Eigen::Vector2d velocity_at(const std::vector<MotionPiece>& motion, double t);
// Total duration of a motion [s].
double duration(const std::vector<MotionPiece>& motion);

std::vector<std::string> trajectory_presets();
// A preset by name, or a YAML file. Throws InputError (file, line, problem).
Trajectory load_trajectory(const std::string& name_or_file);

}  // namespace omnivert::sim
