#pragma once
// Synthetic calibration runs with ground truth, for tests and the Monte-Carlo study: a
// differential-drive robot drives a trajectory, the wheel encoders report the travel with
// Chong-Kleeman noise (eq. 31), and the camera reports bearings of vertical lines (point
// features in the plane) with Gaussian noise. Poses follow eq. (14) exactly, bearings
// follow beta = atan2(y_f - y_C, x_f - x_C) - (theta_R + phi + psi) (docs/theory/conventions.md).
// (Images are the simulator's business, src/sim; this works on bearings only.)

#include <cstdint>
#include <map>
#include <vector>

#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

enum class Trajectory {
  kPaper,     // straight `straight_length` then a turn in place of `turn_angle` (Sec. 9.2)
  kZigzag,    // `zigzag_legs` straights of straight_length / legs, turns of +-zigzag_turn
  kStraight,  // straight only (rho, phi, psi individually unobservable, Sec. 8.1)
};

struct SyntheticRunOptions {
  Trajectory trajectory = Trajectory::kPaper;
  double straight_length = 2.3;                // [m]
  double step = 0.038;                         // travel per frame on straights [m]
  double turn_angle = 3.14159265358979323846;  // kPaper [rad]
  double turn_step = 0.06;                     // rotation per frame in turns [rad]
  int zigzag_legs = 4;
  double zigzag_turn = 1.5707963267948966;  // [rad]
  int num_features = 10;
  double min_distance = 1.5;  // features' distance from the path [m]
  double max_distance = 6.0;
  double wheel_base = 0.5;                                      // e [m]
  double odometry_K = 1e-5;                                     // true K of eq. (31) [m]
  double bearing_sigma = 0.3 * 3.14159265358979323846 / 180.0;  // [rad]
  // Correlation of a track's bearing errors from one frame to the next (AR(1) coefficient;
  // the variance stays bearing_sigma^2): an extracted edge's error changes slowly. 0: white.
  double bearing_correlation = 0.0;
  // A constant bearing error per line, N(0, track_bias_sigma^2), added to all its bearings
  // (CalibrationOptions::noise.track_bias_sigma); drawn from its own generator, so 0 leaves the run
  // as before.
  double track_bias_sigma = 0.0;        // [rad]
  Extrinsics truth{-0.34, 0.23, 0.33};  // the paper's estimate (Sec. 9.2)
  // Each track is cut into pieces (new track ids) with this probability per frame; 0: every
  // feature is one track over the whole run (the camera sees all around).
  double break_probability = 0.0;
  // [m] A feature is seen only from camera positions within this distance (0: from
  // everywhere); a feature seen again after it was out of range is a new track, as a tracker
  // that lost it would report. With a long zigzag, a run whose features enter and leave the
  // view as on a tour of a building (the filter marginalises the tracks that ended).
  double visible_range = 0.0;
  std::uint64_t seed = 1;
};

struct SyntheticRun {
  CalibrationRun run;                       // what the filter sees
  std::vector<Eigen::Vector3d> true_poses;  // per frame (x, y, theta), frame 0 at origin
  std::vector<Eigen::Vector2d> features;    // world points
  std::map<int, int> track_feature;         // track id -> index in features
  Extrinsics truth;
};

// Throws InputError on options that make no run (non-positive lengths, too few features).
SyntheticRun make_synthetic_run(const SyntheticRunOptions& options);

}  // namespace omnivert::calib
