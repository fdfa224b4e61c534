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

#include <limits>
#include <map>
#include <string>
#include <vector>

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
  // slack keeps the problem well posed. Measured (docs/calib.md, "Session 7"): 1e-4 made
  // every batch conservative (from pixels, zigzag NEES 1.8-1.9; synthetic refinement 1.95
  // on seeds 51-100); 1e-5 is consistent on both. (Session 6 had rejected 1e-5 because the
  // corridor zigzag filter then diverged: a rounding failure in the window's covariance,
  // fixed since.) A robot that slips sideways needs more: --lateral-sigma.
  double lateral_sigma = 1e-5;
  bool robust = false;              // Huber loss on bearings
  double huber_sigmas = 3.0;        // Huber threshold in bearing sigmas
  int max_iterations = 100;
  // Track splitting: a track whose bearings are better explained by two features (before
  // and after one frame) than by one, with a likelihood-ratio statistic above split_chi2, is
  // taken to have slipped onto a neighbouring line and is split in two (each part at least
  // split_min_bearings long); 0 turns it off. docs/calib.md ("The office yaw bias").
  double split_chi2 = 20.0;
  int split_min_bearings = 5;
  double split_keep_fraction = 0.5;  // a round splits the tracks within this factor of the
                                     // strongest statistic (the rest are judged after re-solving)
  int split_rounds = 10;
  // Pieces of one line: a track that starts within Options::max_missed_frames frames after
  // another ended, and whose bearings one point explains with the other's (a Wald test with
  // the whole problem's covariance, chi-square(2) at Options::gate_probability), is taken for
  // the same line, lost and found again by the tracker under a new id, and joined to it
  // (docs/calib.md, "Broken tracks"). false: off.
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

// How large the extrinsics' error is, measured by the data (batch.cpp, noise_check). The
// model covariance of (phi, rho, psi) assumes independent bearings of sigma
// options.bearing_sigma; `bearing_part` is the share of it due to the bearings. The
// cluster-robust (jackknife) estimate of that share, with each track's bearings as one
// cluster, is `bearing_clustered`; scale = tr(bearing_part^-1 bearing_clustered) / 3 is 1 on
// average when the assumed noise is right and above 1 when the bearings are noisier or
// correlated along tracks (then sigma x sqrt(scale) is the independent noise that would do
// the same harm). covariance = model + (scale - 1) bearing_part.
// The wheel check: per frame, the wheels' rotation (eq. 15) minus the robot's at a batch
// solution (where the bearings fix the heading far better than the wheels, in turns),
// regressed on the solution's rotation and the distance rolled, with the weights of the
// odometry model (eq. 31, K x1): wheels' turn = (1 + rotation_scale) x the robot's
// + drift_per_m [rad/m] x distance + noise. rotation_scale: the wheel base in the model is
// (1 + s) times too short (a wheel base e (1 + s) fits); drift_per_m: a rotation the wheels
// report while rolling straight (right and left wheel scales |drift| x e apart). (The robot's
// rotation, not the wheels', is the regressor: the wheels' own noise in it would bias the
// scale towards 0 - 1 / (its information), -0.2 % on the synthetic paper runs.) Both are 0
// under the model; `chi2` is the pair's chi-square(2) statistic against it. A systematic
// wheel error is what the paper's five-fold K inflation guards against; this says when there
// is one, and how large.
struct WheelCheck {
  bool ok = false;
  double rotation_scale = 0.0, sigma_rotation_scale = 0.0;
  double drift_per_m = 0.0, sigma_drift_per_m = 0.0;
  double chi2 = 0.0;
  int frames = 0;  // frames with motion used
  double wheel_base = 0.0;  // [m], the model's e
};

struct BatchNoiseCheck {
  WheelCheck wheels;
  bool ok = false;
  double scale = std::numeric_limits<double>::quiet_NaN();
  int clusters = 0;  // tracks
  Eigen::Matrix3d model_covariance = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d bearing_part = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d bearing_clustered = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

// Whether a check shows more noise than the model allows: its scale above the 1 - level
// quantile of chi-square(G) / G over its G tracks (the scale's distribution under the model;
// 50 synthetic runs with 10 tracks: quartiles 0.68 / 0.90 / 1.18 against 0.67 / 0.93 / 1.25).
// false when the check failed or has fewer than 2 tracks.
bool noise_check_rejects_model(const BatchNoiseCheck& check, double level = 0.01);
// Whether a check shows less noise than the model assumes: its scale below the `level`
// quantile of chi-square(G) / G. calibrate() shrinks the bearings' share of the covariance
// by it only where the tracker kept its lines (CalibrateOptions::noise_check): pieces of one
// line left apart look like independent tracks to the check, which then reads less noise
// than there is (docs/calib.md, "The noise check"). false when the check failed, has fewer
// than 2 tracks, or level is not in (0, 0.5).
bool noise_check_finds_less_noise(const BatchNoiseCheck& check, double level = 0.01);
// The two tests above together, "more noise" at `level`, "less noise" at `lower_level`
// (under the model, "agrees" with probability 1 - level - lower_level).
enum class NoiseVerdict { kAgrees, kMoreNoise, kLessNoise };
NoiseVerdict noise_check_verdict(const BatchNoiseCheck& check,
                                 double level = 0.01,
                                 double lower_level = 0.01);
// Whether the wheel check shows a systematic wheel error: its chi-square(2) statistic above
// the 1 - level quantile (0.999: 13.8). false when the check was not made.
bool wheel_check_rejects_model(const WheelCheck& check, double level = 0.001);
// The scale above which noise_check_rejects_model: the 1 - level quantile of
// chi-square(tracks) / tracks.
double noise_check_limit(int tracks, double level = 0.01);
// The scale below which noise_check_finds_less_noise: the level quantile of
// chi-square(tracks) / tracks.
double noise_check_lower_limit(int tracks, double level = 0.01);

struct RefinementResult {
  bool converged = false;
  BatchPoint solution;
  Extrinsics extrinsics;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
  bool covariance_ok = false;  // false when the problem is rank deficient (not observable)
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;
  int num_bearings = 0;  // bearings used
  int num_rejected = 0;  // bearings removed as outliers (|residual| > the filter's gate)
  int num_features = 0;  // tracks in the problem (after splitting)
  int num_splits = 0;    // tracks split in two (BatchOptions::split_chi2)
  // (track id, first frame of the new part): the tracker's id, or with merges the id of the
  // line's first piece.
  std::vector<std::pair<int, int>> splits;
  // Pieces of one line joined (BatchOptions::merge_pieces): (earlier track id, later track
  // id), the later piece's bearings renamed to the line's first piece.
  std::vector<std::pair<int, int>> merges;
  // Bearings left out where lines cross (Options::crossing_guard): (track id of the solved
  // run, i.e. of solved_run when tracks were split or merged, frame).
  std::vector<std::pair<int, int>> guarded;
  // Bearings removed as outliers (the gate) or with a feature left with too few bearings:
  // (track id of the solved run, frame). With `guarded`, what the solution did not use; the
  // bound of Sec. 8.1 for this run is computed without them (calibrate()).
  std::vector<std::pair<int, int>> rejected;
  // With splits or merges (renamed()): the run `solution` refers to (split parts and merged
  // pieces renamed); otherwise empty, and `solution` refers to the run given.
  CalibrationRun solved_run;
  bool renamed() const { return num_splits > 0 || !merges.empty(); }
  // Scale of the bearing residuals at the solution, outliers removed [rad]: 1.4826 x median
  // |residual| x sqrt(bearings / (bearings - 2 features - 3)); the bearing noise the data
  // has (infinity without redundancy).
  double bearing_residual_sigma = std::numeric_limits<double>::infinity();
  BatchNoiseCheck noise;  // at the solution (outliers removed, splits made)
  std::string report;    // Ceres' brief report
};

// Batch maximum-likelihood refinement over the whole run (Ceres, Levenberg-Marquardt),
// started from `start`, with the covariance of (phi, rho, psi) from ceres::Covariance.
// Bearings whose residual exceeds the filter's chi-square gate (options.gate_probability)
// at the solution are removed and the problem solved again (up to three rounds).
RefinementResult refine_batch(const CalibrationRun& run,
                              const Options& options,
                              const BatchPoint& start,
                              const BatchOptions& batch = {});

// Delayed initialisation of the filter (FeatureInit::kAnchoredInverseDepth with
// options.bootstrap_frames > 0): the first frames are solved as a small batch maximum a
// posteriori problem (the prior on phi, rho, psi, an inverse-depth prior N(q0, sigma_q^2)
// along each track's first ray, odometry, bearings; Levenberg-Marquardt relinearises), and
// the filter starts at the last of them from that solution and its covariance (inverse of
// the Fisher information with the priors), carried to the filter's coordinates (camera pose;
// each track as an anchored inverse-depth point anchored at the camera) through central
// differences. This removes the early-update inconsistency measured in NOTES Sec. 5 and in
// docs/calib.md: one linearisation per frame while depth and camera yaw are both unknown.
// Tracks with fewer than 2 bearings in the window are left out (they enter afterwards).
// Outlying bearings are removed as in refine_batch.
// Tracks that slipped onto a neighbouring line are split as in refine_batch
// (options.split_chi2); the later part of such a track enters the state under the tracker's id.
// Returns false (state untouched, reason in *why) when the window cannot be solved.
struct BootstrapDetails {
  // Every track of the window's solution as (D, theta) from the robot at its last window
  // frame (frame = index in the window), with covariance: tracks that ended inside the window
  // never enter the state, and the refinement starts from these. A split track: its latest
  // part.
  std::map<int, TrackEstimate> tracks;
  std::vector<std::pair<int, int>> splits;  // (tracker's track id, window frame of the new part)
  std::vector<std::pair<int, int>> guarded;  // (tracker's track id, window frame) left out
                                             // where lines cross (Options::crossing_guard)
  // (tracker's track id, window frame) removed as outliers (the gate) or with a feature left
  // without bearings: with `guarded`, what the window's solution did not use.
  std::vector<std::pair<int, int>> rejected;
  // Pieces of one line joined in the window (find_merges, Options::join_pieces): (tracker's
  // id of an earlier piece, of the piece joined to it). The line's feature is in the state
  // under its first piece's id; the filter takes later bearings of any of its pieces for it.
  std::vector<std::pair<int, int>> joins;
};
// The camera's yaw phi + psi as the bearings' flow shows it, without any estimate: while the
// robot drives, each line's bearing moves away from the direction of travel (a camera moving
// at velocity v sees a point at distance d and world direction alpha turn at
// |v| sin(alpha - alpha_v) / d), and that direction is -(phi + psi) in the camera's frame
// (eq. 30 with the camera moving along the robot's heading). Each track's inverse distance is
// fitted for each candidate yaw; the yaw whose fits explain most of the flow is returned. NaN
// when the run has too little translation or flow to tell (fewer than `min_pairs` bearing
// pairs, or less than `min_explained` of the flow's sum of squares explained).
// Why (docs/calib.md, "Window starts", session 16): the window's starts kept the prior's
// camera yaw, and a camera mounted 80-110 degrees from it left all five starts far off.
double camera_yaw_from_flow(const CalibrationRun& run,
                            double wheel_base,
                            int min_pairs = 20,
                            double min_explained = 0.3);

bool bootstrap_filter_state(const CalibrationRun& window,
                            const Options& options,
                            FilterState* state,
                            std::string* why = nullptr,
                            BootstrapDetails* details = nullptr);

// The run with tracks split at the given (tracker's track id, first frame of the new part)
// pairs (RefinementResult::splits, FilterResult::splits): each part between consecutive split
// frames of a track gets a new id, from one above the largest id of the run. `origin`
// (optional) receives new id -> tracker's id.
CalibrationRun split_tracks(const CalibrationRun& run,
                            const std::vector<std::pair<int, int>>& splits,
                            std::map<int, int>* origin = nullptr);

// The run with pieces of one line under one id (RefinementResult::merges,
// FilterResult::joins: pairs (earlier piece's id, joined piece's id)): each joined piece takes
// the id of its line's first piece (chains followed). `renamed` (optional) receives each
// renamed id -> its new id.
CalibrationRun join_tracks(const CalibrationRun& run,
                           const std::vector<std::pair<int, int>>& joins,
                           std::map<int, int>* renamed = nullptr);
// Each joined piece's line: joined piece's id -> the id of its line's first piece (chains of
// (earlier, later) pairs followed to their start). What join_tracks renames by. Of several
// pairs for one piece the last counts; a pair that joins a piece to itself or would close a
// loop is left out: every chain ends.
std::map<int, int> join_roots(const std::vector<std::pair<int, int>>& joins);

// Verdict on one parameter (or combination) of the extrinsics.
struct ParameterVerdict {
  bool determined = false;
  double crlb = 0.0;  // Cramer-Rao standard deviation (infinity when not determined)
};

struct ObservabilityOptions {
  double max_sigma_angle = 0.035;            // [rad] (2 degrees) an angle with a larger bound is
                                             // reported as not determined
  double max_sigma_rho = 0.02;               // [m]
  double relative_eigenvalue_floor = 1e-9;   // eigenvalues below floor * max count as zero
  // phi, rho and psi individually need the robot to turn (Sec. 8.1). A run whose heading
  // spans less than this many sigmas of its own odometry noise did not turn: the bounds at
  // its estimated trajectory come from heading noise (a straight run at 0.025 degree of
  // bearing noise: rho's bound 15.6 mm, under the 2 cm above), and they are not determined.
  double min_rotation_sigmas = 5.0;
                                             // (numerical null directions reach 2e-12)
};

// Sec. 8.1 for a recorded trajectory, from the Fisher information J^T Sigma^-1 J of the batch
// problem at `at`, marginalised onto (phi, rho, psi) (Schur complement).
struct ObservabilityReport {
  ParameterVerdict phi, rho, psi;
  ParameterVerdict yaw;                                   // phi + psi
  ParameterVerdict x, y;                                  // camera position rho (cos phi, sin phi)
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();  // marginal Fisher information
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();  // of the information scaled by
                                                          // the thresholds (dimensionless)
  double heading_range = 0.0;  // [rad] max - min of the robot's heading along the run
  double heading_noise = 0.0;  // [rad] sigma of the heading odometry alone accumulates (eq. 31)
  int rank = 0;            // numerical rank of the marginal information
  double condition = 0.0;  // its condition number (scaled), infinity when singular
  Eigen::Matrix3d crlb_covariance = Eigen::Matrix3d::Zero();  // inverse information
  bool all_determined() const { return phi.determined && rho.determined && psi.determined; }
  std::string message;  // what is (not) determined and the motion that would fix it
};

ObservabilityReport analyse_observability(const CalibrationRun& run,
                                          const Options& options,
                                          const BatchPoint& at,
                                          const BatchOptions& batch = {},
                                          const ObservabilityOptions& obs = {});

}  // namespace omnivert::calib
