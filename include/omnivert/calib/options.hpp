#pragma once
// Every option of the camera-to-odometry self-calibration (paper Sec. 7-8), as one tree:
//
//   calib::CalibrationOptions options;          // == calib::recommended_options()
//   options.robot.wheel_base = 0.42;            // e of eq. (15) [m]
//   options.refinement.enabled = true;          // the batch maximum-likelihood refinement
//   std::string why;
//   if (!options.IsValid(&why)) ...             // why names the field, e.g. "noise.bearing_sigma"
//   auto result = calib::calibrate(run, options);
//
// A default-constructed tree is recommended_options(): the bearing sigma our extractor has on
// rendered images (0.025 degree; docs/theory/filter.md#observation) and the Chong-Kleeman K as
// given. The paper's values (Sec. 8.2: 0.3 degree, K inflated five-fold) are one call away:
// paper_options(). Each option is defined once; the filter, its start-up window, the
// refinement and the bound of Sec. 8.1 read the same fields.

#include <cstddef>
#include <functional>
#include <string>

#include <Eigen/Core>

#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

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

// The robot: its wheels and their odometry model.
struct RobotModel {
  double wheel_base = 0.5;  // e of eq. (15) [m]
  // Chong-Kleeman odometry model, eq. (31): var(d) = K |d| (+ variance_floor), per wheel.
  double odometry_K = 1e-5;                // [m]
  double odometry_variance_floor = 1e-12;  // [m^2], keeps the noise positive at rest
  // [m] per step. Eq. (14)-(15) (and the filter's eq. 29) have no lateral motion; a small
  // slack keeps the batch problems (window, refinement, bound) well posed and is the noise of
  // the filter's sideways displacement (FrameInput::lateral). 1e-4 makes every batch
  // conservative (from pixels, zigzag NEES 1.8-1.9; synthetic refinement 1.95 over 50 runs);
  // 1e-5 is consistent on both (docs/theory/refinement.md#odometry-factor). A robot that
  // slips sideways needs more: --lateral-sigma.
  double lateral_sigma = 1e-5;
};

// The bearings' noise (eq. 30).
struct BearingNoise {
  // [rad] 0.025 degree: what our extractor's bearings have on rendered images
  // (docs/theory/filter.md#observation); the paper used 0.3 degree (paper_options()).
  double bearing_sigma = 0.025 * 3.14159265358979323846 / 180.0;
  // [rad] A constant bearing error per track, b ~ N(0, track_bias_sigma^2) (0: none). Each
  // bearing is then predicted as eq. (30) + b, with bearing_sigma the error that changes from
  // frame to frame. The filter carries b as one more entry of the track's block; the batch
  // problems (window, refinement, bound) as one parameter per track with that prior. Against
  // the ground truth our extractor's bearings have both parts
  // (docs/theory/filter.md#per-track-bias).
  double track_bias_sigma = 0.0;
};

// Prior on (phi, rho, psi): the paper's hand measurement with wide sigmas.
struct Prior {
  Extrinsics mean{0.0, 0.2, 0.0};
  Eigen::Vector3d sigma{0.8, 0.1, 0.8};  // [rad, m, rad]
};

// The EKF of Sec. 8.2 and its start-up window.
struct FilterOptions {
  // Factor on K in the filter. The paper (Sec. 8.2, before eq. 31) uses 5, "to make the method
  // robust with respect to the system non-linearities"; our feature initialisation already
  // keeps the filter consistent from the rough prior at 1, and 5 costs efficiency when K is
  // right (docs/theory/filter.md#odometry-noise): 1 by default; paper_options() sets 5.
  double odometry_inflation = 1.0;
  // Feature initialisation.
  FeatureInit feature_init = FeatureInit::kAnchoredInverseDepth;
  double naive_distance = 3.0;         // D0 [m] (kNaive)
  double naive_distance_sigma = 2.0;   // [m] (kNaive)
  double min_feature_distance = 1.0;   // [m] (kInverseDistance: 2-sigma range of the prior)
  double max_feature_distance = 20.0;  // [m]
  double convert_ratio = 0.05;         // sigma_D / D below which (q, theta) -> (D, theta); 0: never
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
  // Updates.
  bool second_order_noise = true;  // add 1/2 tr(Hxx P Hxx P) to each bearing's variance
  // 1: the plain EKF (linearised at the prediction); >1: the iterated EKF (Gauss-Newton), which
  // ends biased and overconfident on long runs (docs/theory/filter.md#updates).
  int update_iterations = 1;
};

// Which bearings belong together, in the filter, its window and the refinement alike.
struct AssociationOptions {
  double gate_probability = 0.999;  // chi-square gate of each bearing (1 dof); 1: no gate
  int max_missed_frames = 20;       // a track not seen for this many frames has ended
  int min_track_length = 3;         // batch/observability: shorter tracks are ignored
  // A feature that a batch solve (window, refinement) puts closer than this to the camera at
  // a frame that sees it has collapsed onto the camera, where its bearing (eq. 30) is not
  // defined and its information without bound (the filter's sigmas collapse; regression test
  // CalibrationFilter.AFeatureCollapsedOntoTheCameraIsLeftOut). Such a feature is left out
  // with its bearings.
  double min_feature_range = 0.05;  // [m]
  // Crossing guard [rad]: a bearing is not used while another feature's predicted bearing
  // is within this angle of its own (filter: features in the state; batches: tracks over
  // their span). The extractor merges two lines that close into one detection, whose
  // bearing is pulled towards the other line; 0: off. 0.75 degree: from pixels, bearings
  // within 0.5-0.75 degree of another line are off by 0.04-0.08 degree RMS, against 0.01-0.03
  // beyond 1 degree; 1 degree leaves out up to two thirds of the hall's bearings
  // (docs/theory/association.md#lines-that-cross).
  double crossing_guard = 0.75 * 3.14159265358979323846 / 180.0;
  // Pieces of one line: the tracker lost a line and found it again under a new id. The batch
  // problems (window, refinement) join a track that starts within max_missed_frames frames
  // after another ended, and whose bearings one point explains with the other's (a Wald test
  // with the whole problem's covariance, chi-square(2) at gate_probability). After the window
  // the filter continues a feature of the state, whose point is known (converted,
  // convert_ratio) and which is not seen in this frame, with a track that starts where it is
  // predicted (its first bearing within the gate of that feature and of no other, no other
  // new track claiming it, and no feature seen in this frame within crossing_guard of it).
  // Kept apart, the pieces act as independent features and the filter is overconfident
  // (docs/theory/association.md#pieces-of-one-line). false: off.
  bool join_pieces = true;
  // The filter joins only where the feature's predicted bearing is sharp: its sigma (from the
  // state's covariance, sqrt(H P H^T)) at most this many bearing sigmas. A wide prediction
  // lets the new track of another line pass its gate, and a wrong join biases the filter for
  // the rest of a long run (docs/theory/association.md#pieces-of-one-line). 0: no limit.
  double join_prediction_sigmas = 4.0;
  // Track splitting (window and refinement): a track whose bearings are better explained by
  // two features (before and after one frame) than by one, with a likelihood-ratio statistic
  // above split_chi2, is taken to have slipped onto a neighbouring line and is split in two
  // (each part at least split_min_bearings long); 0 turns it off
  // (docs/theory/association.md#slipped-tracks).
  double split_chi2 = 20.0;
  int split_min_bearings = 5;
  // A round splits the tracks within this factor of the strongest statistic among the tracks
  // whose frames overlap their own (the rest are judged after re-solving); a split track's
  // parts are split again in the same round where their own statistic passes.
  double split_keep_fraction = 0.5;
  int split_rounds = 10;
};

// The batch maximum-likelihood refinement over the whole run (Ceres).
struct RefinementOptions {
  bool enabled = false;
  // The batch problems (window, refinement, bound) use K x this (the filter's inflation is a
  // robustness device of the EKF, not of the maximum-likelihood problem).
  double odometry_inflation = 1.0;
  bool robust = false;        // Huber loss on bearings
  double huber_sigmas = 3.0;  // Huber threshold in bearing sigmas
  int max_iterations = 100;
  // The solves before and between the association's decisions (outliers, crossings, joins,
  // splits) stop when an iteration changes the cost by less than this fraction; the last
  // solve, whose answer is reported, at 1e-10. Each decision needs the solution to a
  // fraction of a sigma, not to the last digit.
  double association_function_tolerance = 1e-6;
  // A run of at least two windows starts from poses and features solved window by window,
  // this many frames each overlapping by warm_start_overlap, instead of dead reckoning: over a
  // long run dead reckoning drifts, and the whole-run solve would spend most of its iterations
  // taking the drift out (docs/theory/refinement.md#long-runs). 0: off.
  int warm_start_window = 150;
  int warm_start_overlap = 30;
  // With the run's CalibrationRun::clock: a correction dS of the camera-odometry time offset
  // estimated with the extrinsics (the image stamps late by a further dS; docs/calibration.md
  // #time-offset), with the prior dS ~ N(0, time_offset_prior_sigma_s^2) that keeps a run
  // without a change of motion (where dS moves nothing) well posed.
  bool estimate_time_offset = false;
  double time_offset_prior_sigma_s = 0.1;
};

// The data's check of the bearing noise (BatchNoiseCheck, at a batch solution).
struct NoiseCheckOptions {
  // Where the check shows more noise than the model allows (noise_check_verdict), the reported
  // covariance becomes the checked one. The refinement's: model + (scale - 1) x its bearing
  // part. The filter's: scaled by the overall variance ratio tr(model^-1 checked) / 3 of a
  // check on its own tracks (split only where its window split them), a batch solved for the
  // check alone. Where it shows less noise than the model assumes, the bearings' share of the
  // covariance is shrunk the same way (the refinement's: the checked covariance; the filter's:
  // plus the checked minus the model covariance of its own check), but only when the tracker
  // kept its lines: at most lower_max_joins pieces joined per track checked. A tracker that
  // loses lines leaves pieces of one line that the joins miss, independent tracks to the
  // check, which then reads less noise than there is: runs with tracks broken every ~10
  // frames join 2.6-7.4 pieces per track (our tracker's runs from pixels at most 0.6), and
  // shrunk they would be overconfident (docs/theory/noise-check.md#verdicts). Otherwise the
  // verdict is reported and the covariances kept (noise_check_line names the sigma the data
  // want). false: no check, the model's covariances.
  bool enabled = true;
  // The levels of noise_check_verdict's two sides. "More noise" at 1%: enlarging sigmas that
  // were right costs accuracy nowhere and is rare. "Less noise" at 20%: when the model is
  // right, 1 run in 5 is shrunk, a mean NEES 0.10-0.15 higher (synthetic, 0.03 degree, 200
  // runs: still inside the 95% interval [2.67, 3.35]); where the model's sigma is too large,
  // most runs are (from pixels, corridor, paper trajectory, 188 of 200 runs; at 1% 74 of 200;
  // docs/theory/noise-check.md#verdicts).
  double level = 0.01;
  double lower_level = 0.2;
  // Pieces joined per track checked above which "less noise" is reported, not applied (< 0:
  // never applied).
  double lower_max_joins = 0.5;
  // The check inverts the information matrix densely up to this many variables, and uses
  // sparse solves above (the same numbers; tested).
  int dense_limit = 3000;
  // A track of at most this many bearings gets (I - H_cc)^-1/2 r_c from the eigen-
  // decomposition of its leverage H_cc, whose cost grows with the cube of its length (a line
  // seen along a whole 2,367-frame run); a longer one by the Lanczos iteration on products
  // with F^-1 (the same numbers to about 1e-9 relative; tested).
  int dense_track_limit = 400;
};

// When the bound of Sec. 8.1 calls a parameter determined.
struct ObservabilityOptions {
  double max_sigma_angle = 0.035;           // [rad] (2 degrees) an angle with a larger bound is
                                            // reported as not determined
  double max_sigma_rho = 0.02;              // [m]
  double relative_eigenvalue_floor = 1e-9;  // eigenvalues below floor * max count as zero
                                            // (numerical null directions reach 2e-12)
  // phi, rho and psi individually need the robot to turn (Sec. 8.1). A run whose heading
  // spans less than this many sigmas of its own odometry noise did not turn: the bounds at
  // its estimated trajectory come from heading noise (a straight run at 0.025 degree of
  // bearing noise: rho's bound 15.6 mm, under the 2 cm above), and they are not determined.
  double min_rotation_sigmas = 5.0;
  // The marginal information of (phi, rho, psi) is computed on the problem's sparse structure
  // (each track eliminated on its own, then the poses' chain by a sparse LDLT: linear in the
  // run's length). true: the plain reference instead, the whole nuisance block eigen-
  // decomposed (cubic in the run's length, quadratic in memory: for tests; the same numbers
  // to 1e-6, docs/calibration.md#cramer-rao-bounds).
  bool dense_reference = false;
};

struct CalibrationOptions {
  RobotModel robot;
  BearingNoise noise;
  Prior prior;
  FilterOptions filter;
  AssociationOptions association;
  RefinementOptions refinement;
  NoiseCheckOptions noise_check;
  ObservabilityOptions observability;
  // Threads the estimators may use side by side (the filter's noise check beside the
  // refinement): 0 every core, 1 one after the other. The results are the same to the bit.
  int threads = 0;
  // Long work reported as it goes (null: nothing), always on the calling thread: `stage` is
  // "filter" (`done` frames of `total`), "refinement: warm start" (windows of `total`),
  // "refinement: first solve", "refinement: joining pieces" and "refinement: splitting tracks"
  // (`done` the round, `total` 0: the rounds end when nothing more joins or splits), and
  // "refinement: covariance". The results do not depend on it.
  std::function<void(const std::string& stage, std::size_t done, std::size_t total)> progress;

  // True when the whole tree is usable; otherwise false with the reason in *why (may be
  // null), which names the offending field by its path, e.g. "noise.bearing_sigma must be > 0".
  bool IsValid(std::string* why) const;
};

// Presets. recommended_options(): CalibrationOptions{}, the defaults of `omnivert calibrate`
// and of pipeline::calibrate_dataset (bearing sigma 0.025 degree, K as given).
// paper_options(): Sec. 8.2 as published, bearing sigma 0.3 degree and the Chong-Kleeman K
// inflated five-fold in the filter.
CalibrationOptions recommended_options();
CalibrationOptions paper_options();

}  // namespace omnivert::calib
