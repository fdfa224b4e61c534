#pragma once
// Checks of the model by the data, at a batch solution (refine_batch): the bearing noise
// (BatchNoiseCheck) and the wheel odometry (WheelCheck), and their verdicts.

#include <limits>

#include <Eigen/Core>

namespace omnivert::calib {

// How large the extrinsics' error is, measured by the data (batch.cpp, noise_check). The
// model covariance of (phi, rho, psi) assumes independent bearings of sigma
// options.noise.bearing_sigma; `bearing_part` is the share of it due to the bearings. The
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
  int frames = 0;           // frames with motion used
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
// by it only where the tracker kept its lines (CalibrationOptions::noise_check): pieces of one
// line left apart look like independent tracks to the check, which then reads less noise
// than there is (docs/theory/noise-check.md). false when the check failed, has fewer
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

}  // namespace omnivert::calib
