#pragma once
// The batch (whole-run) formulation of the calibration problem, shared by the maximum
// likelihood refinement (Ceres) and the observability / Cramer-Rao analysis:
//   unknowns: robot poses (x, y, theta) of frames 1..N (frame 0 is the origin: the gauge),
//             features as world points (x_f, y_f), extrinsics (phi, rho, psi);
//   factors:  odometry between consecutive frames, eq. (14)-(15), with the Chong-Kleeman
//             covariance of the wheel travels, eq. (31); a bearing per observation,
//             beta = atan2(y_f - y_C, x_f - x_C) - (theta_R + phi + psi) (eq. 16-17).
// The odometry factor has three residuals: the two wheel travels implied by the pose change
// (eq. 14-15 inverted) against the encoders, and the lateral slip, which a differential drive
// cannot do (sigma `lateral_sigma`).

#include <map>
#include <vector>

#include <Eigen/Core>

#include "omnivert/calib/calibration_filter.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

// A point of the batch problem.
struct BatchPoint {
  std::vector<Eigen::Vector3d> poses;       // one per frame, poses[0] = (0, 0, 0)
  std::map<int, Eigen::Vector2d> features;  // track id -> world point
  Extrinsics extrinsics;
};

struct BatchOptions {
  double odometry_inflation = 1.0;  // the batch uses K * this (the filter's inflation is a
                                    // robustness device of the EKF, not of the ML problem)
  // [m] per step. Eq. (14)-(15) (and the filter's eq. 29) have no lateral motion; a small
  // slack keeps the problem well posed. 1e-4 makes every batch conservative (from pixels,
  // zigzag NEES 1.8-1.9; synthetic refinement 1.95 over 50 runs); 1e-5 is consistent on both
  // (docs/theory/refinement.md#odometry-factor). A robot that slips sideways needs more:
  // --lateral-sigma.
  double lateral_sigma = 1e-5;
  bool robust = false;        // Huber loss on bearings
  double huber_sigmas = 3.0;  // Huber threshold in bearing sigmas
  int max_iterations = 100;
  // Track splitting: a track whose bearings are better explained by two features (before
  // and after one frame) than by one, with a likelihood-ratio statistic above split_chi2, is
  // taken to have slipped onto a neighbouring line and is split in two (each part at least
  // split_min_bearings long); 0 turns it off
  // (docs/theory/association.md#slipped-tracks).
  double split_chi2 = 20.0;
  int split_min_bearings = 5;
  double split_keep_fraction = 0.5;  // a round splits the tracks within this factor of the
                                     // strongest statistic (the rest are judged after re-solving)
  int split_rounds = 10;
  // Pieces of one line: a track that starts within Options::max_missed_frames frames after
  // another ended, and whose bearings one point explains with the other's (a Wald test with
  // the whole problem's covariance, chi-square(2) at Options::gate_probability), is taken for
  // the same line, lost and found again by the tracker under a new id, and joined to it
  // (docs/theory/association.md#pieces-of-one-line). false: off.
  bool merge_pieces = true;
  // The noise check (BatchNoiseCheck) inverts the information matrix densely up to this many
  // variables, and uses sparse solves above (the same numbers; tested).
  int noise_check_dense_limit = 3000;
  // Only tracks with at least options.min_track_length bearings enter the batch.
};

// Dead-reckoned poses, eq. (14), from the encoder increments.
std::vector<Eigen::Vector3d> dead_reckoning(const CalibrationRun& run, double wheel_base);

// A starting point from a filter run: dead-reckoned poses, each track's last filter estimate
// (D, theta) placed in the world from its frame's pose, the filter's extrinsics.
BatchPoint batch_point_from_filter(const CalibrationRun& run,
                                   const Options& options,
                                   const FilterResult& filter);

}  // namespace omnivert::calib
