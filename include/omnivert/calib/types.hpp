#pragma once
// Inputs and options of the camera-to-odometry self-calibration (paper Sec. 7-8).
//
// Conventions (docs/theory/conventions.md): robot frame x forward, y left, z up; the camera centre
// is at rho (cos phi, sin phi) in the robot frame and the camera x-axis is rotated by phi + psi
// from the robot x-axis, so T_base_cam = [Rz(phi + psi) | (rho cos phi, rho sin phi, 0)].
// A bearing beta is counter-clockwise from the camera x-axis, in radians.

#include <Eigen/Core>
#include <string>
#include <vector>

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
  // This bearing's noise sigma is Options::bearing_sigma x sigma_scale (> 0): a crowded
  // line's bearing is noisier (DatasetRunOptions::crowded_sigma_scale).
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

// A whole recorded run (what the batch refinement and the observability analysis need).
struct CalibrationRun {
  std::vector<FrameInput> frames;
};

// How a new feature enters the filter state.
enum class FeatureInit {
  // The "naive" initialisation of docs/theory/filter.md: D from a fixed prior (D0 +- sigma_D0),
  // theta from the far-feature approximation beta ~ pi - theta - phi - psi (eq. 25).
  kNaive,
  // Undelayed inverse-distance initialisation (Civera, Davison, Montiel 2008, adapted to the
  // robot-centric state of eq. 28): the ray of the first bearing from the camera centre with
  // a Gaussian prior on the inverse distance along it; the feature is kept as
  // (q = 1/D, theta) while its distance is poorly known and converted to (D, theta) of
  // eq. (28) once sigma_D / D falls below `convert_ratio`.
  kInverseDistance,
  // The invariant parametrisation (model.hpp): the feature enters as an anchored inverse-depth
  // point (anchor = camera centre, azimuth of the ray, inverse depth q ~ the same prior as
  // kInverseDistance) and becomes a robot-frame point once sigma_q / q < convert_ratio; the
  // extrinsics are carried as the camera pose (c_x, c_y, phi + psi). Same measurements, same
  // models (eq. 14-17, 31); the straight-motion unobservable direction is then a constant
  // vector, which keeps the EKF from inventing information along it.
  kAnchoredInverseDepth,
};

struct Options {
  // Robot.
  double wheel_base = 0.5;  // e of eq. (15) [m]
  // Chong-Kleeman odometry model, eq. (31): var(d) = K |d| (+ variance_floor), per wheel.
  double odometry_K = 1e-5;  // [m]
  // Factor on K. The paper (Sec. 8.2, before eq. 31) uses 5, "to make the method robust with
  // respect to the system non-linearities"; our feature initialisation already keeps the filter
  // consistent from the rough prior at 1, and 5 costs efficiency when K is right
  // (docs/theory/filter.md#odometry-noise): 1 by default; paper_options() sets 5.
  double odometry_inflation = 1.0;
  double odometry_variance_floor = 1e-12;  // [m^2], keeps the noise positive at rest
  // Camera.
  // [rad] The paper's 0.3 degree (Sec. 8.2). recommended_options() sets the 0.025 degree that
  // our extractor's bearings have on rendered images (docs/theory/filter.md#observation).
  double bearing_sigma = 0.3 * 3.14159265358979323846 / 180.0;
  // [rad] A constant bearing error per track, b ~ N(0, track_bias_sigma^2) (0: none). Each
  // bearing is then predicted as eq. (30) + b, with bearing_sigma the error that changes from
  // frame to frame. The filter carries b as one more entry of the track's block
  // (FeatureSlot::bias); the batch problems (window, refinement, bound) as one parameter per
  // track with that prior. Against the ground truth our extractor's bearings have both parts
  // (docs/theory/filter.md#per-track-bias).
  double track_bias_sigma = 0.0;
  // Prior on (phi, rho, psi): the paper's hand measurement with wide sigmas.
  Extrinsics prior{0.0, 0.2, 0.0};
  Eigen::Vector3d prior_sigma{0.8, 0.1, 0.8};  // [rad, m, rad]
  // Feature initialisation.
  FeatureInit feature_init = FeatureInit::kAnchoredInverseDepth;
  double naive_distance = 3.0;         // D0 [m] (kNaive)
  double naive_distance_sigma = 2.0;   // [m] (kNaive)
  double min_feature_distance = 1.0;   // [m] (kInverseDistance: 2-sigma range of the prior)
  double max_feature_distance = 20.0;  // [m]
  // A feature that a batch solve (window, refinement) puts closer than this to the camera at
  // a frame that sees it has collapsed onto the camera, where its bearing (eq. 30) is not
  // defined and its information without bound (the filter's sigmas collapse; regression test
  // CalibrationFilter.AFeatureCollapsedOntoTheCameraIsLeftOut). Such a feature is left out
  // with its bearings.
  double min_feature_range = 0.05;  // [m]
  double convert_ratio = 0.05;      // sigma_D / D below which (q, theta) -> (D, theta); 0: never
  // Delayed initialisation (kAnchoredInverseDepth only): the frames up to the first turn are
  // solved as a batch and the filter starts from that solution (bootstrap_filter_state).
  // While the robot drives straight the camera position is unobservable (Sec. 8.1) and the
  // feature depths and camera yaw are entangled; an EKF linearised once per frame there
  // becomes overconfident (measured: mean NEES in the hundreds), a relinearised batch does
  // not. The window ends at the first frame whose dead-reckoned heading differs from the
  // window's first by bootstrap_rotation, or after bootstrap_max_frames frames (or at
  // finish()). bootstrap_rotation <= 0: no window (the undelayed anchored initialisation).
  double bootstrap_rotation = 1.5;  // [rad] (docs/theory/window.md#where-the-window-ends)
  int bootstrap_min_frames = 5;
  int bootstrap_max_frames = 300;
  double bootstrap_depth_prior_scale = 100.0;  // window's inverse-depth prior sigma, x sigma_q
  // Starts of the window's solve (1-5): the prior, then phi moved by -0.5, +0.5, -1 and +1 rad
  // (psi the other way), in that order; the lowest cost is kept (docs/theory/window.md#starts).
  // Where the bearings' flow puts the camera yaw far from the prior's (camera_yaw_from_flow),
  // the same starts are solved at the flow's camera yaw as well.
  int bootstrap_starts = 5;
  // Tracks that slipped onto a neighbouring line are split in the window's solve, with the
  // refinement's test (BatchOptions::split_chi2, which has the same default); 0: off.
  double split_chi2 = 20.0;
  // Sideways slip per step [m] in the window's odometry factors (BatchOptions::lateral_sigma,
  // which has the same default).
  double lateral_sigma = 1e-5;
  // Updates.
  bool second_order_noise = true;   // add 1/2 tr(Hxx P Hxx P) to each bearing's variance
  int update_iterations = 3;        // 1: plain EKF; >1: iterated EKF (Gauss-Newton)
  double gate_probability = 0.999;  // chi-square gate of each bearing (1 dof); 1: no gate
  int max_missed_frames = 20;       // a track not seen for this many frames has ended
  // Pieces of one line: the tracker lost a line and found it again under a new id. In the
  // start-up window the pieces are joined as the refinement joins them (BatchOptions::
  // merge_pieces); after it, a track that starts where a feature of the state, whose point is
  // known (converted, convert_ratio) and which is not seen in this frame, is predicted (its
  // first bearing within the gate of that feature and of no other, no other new track
  // claiming it, and no feature seen in this frame within crossing_guard of it) continues
  // that feature. Kept apart, the pieces act as independent features and the filter is
  // overconfident (docs/theory/association.md#pieces-of-one-line). false: off.
  bool join_pieces = true;
  int min_track_length = 3;  // batch/observability: shorter tracks are ignored
  // Crossing guard [rad]: a bearing is not used while another feature's predicted bearing
  // is within this angle of its own (filter: features in the state; batches: tracks over
  // their span). The extractor merges two lines that close into one detection, whose
  // bearing is pulled towards the other line; 0: off. 0.75 degree: from pixels, bearings
  // within 0.5-0.75 degree of another line are off by 0.04-0.08 degree RMS, against 0.01-0.03
  // beyond 1 degree; 1 degree leaves out up to two thirds of the hall's bearings
  // (docs/theory/association.md#lines-that-cross).
  double crossing_guard = 0.75 * 3.14159265358979323846 / 180.0;

  // True when usable; otherwise false with the reason in *why (may be null).
  bool IsValid(std::string* why) const;
};

// Presets. recommended_options(): the defaults of `omnivert calibrate` and of
// pipeline::calibrate_dataset: Options{} with the bearing sigma our extractor has on rendered
// images (0.025 degree; docs/theory/filter.md). paper_options(): Sec. 8.2 as published, bearing
// sigma 0.3 degree and the Chong-Kleeman K inflated five-fold.
Options recommended_options();
Options paper_options();

}  // namespace omnivert::calib
