#pragma once
// Inputs of the camera-to-odometry self-calibration (paper Sec. 7-8); its options are in
// options.hpp.
//
// Conventions (docs/theory/conventions.md): robot frame x forward, y left, z up; the camera centre
// is at rho (cos phi, sin phi) in the robot frame and the camera x-axis is rotated by phi + psi
// from the robot x-axis, so T_base_cam = [Rz(phi + psi) | (rho cos phi, rho sin phi, 0)].
// A bearing beta is counter-clockwise from the camera x-axis, in radians.

#include <compare>
#include <map>
#include <memory>
#include <vector>

#include <Eigen/Core>

namespace omnivert::calib {

// The three extrinsic parameters of Fig. 19.
struct Extrinsics {
  double phi = 0.0;  // direction of the camera centre in the robot frame [rad]
  double rho = 0.2;  // distance of the camera centre from the robot origin [m]
  double psi = 0.0;  // camera yaw minus phi [rad]

  Eigen::Vector3d vec() const { return {phi, rho, psi}; }
  static Extrinsics from_vec(const Eigen::Vector3d& v) { return {v(0), v(1), v(2)}; }
  // Camera centre in the robot frame, rho (cos phi, sin phi).
  Eigen::Vector2d position() const;
  // Camera yaw in the robot frame, phi + psi (wrapped).
  double yaw() const;
  // 4x4 homogeneous T_base_cam (z = 0).
  Eigen::Matrix4d T_base_cam() const;
};

// One bearing of a tracked vertical line in one image.
struct BearingObservation {
  int track_id = -1;  // the tracker's id; the same line keeps its id along its track
  double beta = 0.0;  // bearing in the camera frame [rad], any range (wrapped internally)
  // This bearing's noise sigma is CalibrationOptions::noise.bearing_sigma x sigma_scale (> 0):
  // a crowded line's bearing is noisier (DatasetRunOptions::crowded_sigma_scale).
  double sigma_scale = 1.0;
};

// What the CLI feeds per image frame: the wheel travel since the previous frame (zero for
// the first frame) and the bearings seen in this frame.
struct FrameInput {
  double d_right = 0.0;  // right wheel travel since the previous frame [m]
  double d_left = 0.0;   // left wheel travel since the previous frame [m]
  // Sideways displacement over the step [m], perpendicular to the mid-step heading, that
  // eq. (14) applied once per image cannot give: the wheel samples between two images, each
  // integrated by eq. (14), compose to a motion that can have it (a straight that turns
  // within the frame: simulator, paper trajectory, frame 61, 0.47 mm). 0 from a single step.
  double lateral = 0.0;
  // Covariance of (d_right, d_left, lateral) per unit Chong-Kleeman K (eq. 31 applied to each
  // wheel sample, compose_wheel_steps): the sideways displacement composed from noisy samples
  // is noisy too (a heading error early in the frame moves the robot sideways later; about
  // 0.02 mm per frame on the simulator's straights). Zero: one step, diag(|d_right|, |d_left|)
  // and no sideways noise.
  Eigen::Matrix3d covariance_per_K = Eigen::Matrix3d::Zero();
  std::vector<BearingObservation> observations;
};

// The wheels' cumulative travel on the odometry clock and each frame's stamp on it: what the
// refinement needs to estimate a correction of the camera-odometry time offset with the
// extrinsics (RefinementOptions::estimate_time_offset). With the image stamps late by a
// further dS, frame k was taken at odometry time image_t[k] - dS, and the wheel travel
// between two frames is read there (piecewise linear between samples, held beyond the ends).
struct WheelClock {
  std::vector<double> t;            // sample times [s], increasing
  std::vector<double> left, right;  // cumulative travel at t [m]
  std::vector<double> image_t;      // each frame's stamp on the odometry clock [s]
};

// A whole recorded run (what the batch refinement and the observability analysis need).
struct CalibrationRun {
  std::vector<FrameInput> frames;
  // Optional: with RefinementOptions::estimate_time_offset, the refinement estimates the time
  // offset's correction from it (shared: runs are copied as tracks are split and joined).
  std::shared_ptr<const WheelClock> clock;
};

// A point of the batch (whole-run) problem of the refinement and the observability analysis
// (docs/theory/refinement.md): robot poses (x, y, theta) of every frame, poses[0] = (0, 0, 0)
// the gauge; features as world points (x_f, y_f) by track id; the extrinsics.
struct BatchPoint {
  std::vector<Eigen::Vector3d> poses;
  std::map<int, Eigen::Vector2d> features;
  Extrinsics extrinsics;
  // The time offset's correction dS [s] (CalibrationRun::clock), 0 when not estimated.
  double time_offset = 0.0;
};

// One bearing of a run: its track id and its frame (index into CalibrationRun::frames).
// Ordered by track, then frame.
struct BearingKey {
  int track = 0;
  int frame = 0;
  friend auto operator<=>(const BearingKey&, const BearingKey&) = default;
};

// A track split in two where it slipped onto a neighbouring line: the track's id and the
// first frame of the new part (split_tracks, track_ids.hpp).
struct TrackSplit {
  int track = 0;
  int frame = 0;
  friend auto operator<=>(const TrackSplit&, const TrackSplit&) = default;
};

// Two pieces of one line joined: the earlier piece's track id and the later piece's, whose
// bearings become the line's (join_tracks, track_ids.hpp).
struct TrackJoin {
  int earlier = 0;
  int later = 0;
  friend auto operator<=>(const TrackJoin&, const TrackJoin&) = default;
};

}  // namespace omnivert::calib
