#pragma once
// The whole calibration of a recorded run, what `omnivert calibrate` calls:
//   filter (Sec. 8.2) -> observability and Cramer-Rao bounds (Sec. 8.1) -> optional batch
//   maximum-likelihood refinement (Ceres) -> outputs.
//
//   omnivert::calib::CalibrationRun run;              // one FrameInput per image
//   omnivert::calib::CalibrationOptions options;      // options.hpp: robot, noise, prior...
//   options.refinement.enabled = true;
//   auto result = omnivert::calib::calibrate(run, options);
//   if (!result.observability.all_determined() && !force) -> print message, exit code 3
//   omnivert::calib::write_extrinsics_yaml(dir + "/extrinsics.yaml", result);
//   omnivert::calib::write_states_csv(dir + "/states.csv", result.filter.history);

#include <string>
#include <vector>

#include "omnivert/calib/calibration_filter.hpp"
#include "omnivert/calib/diagnostics.hpp"
#include "omnivert/calib/observability.hpp"
#include "omnivert/calib/options.hpp"
#include "omnivert/calib/refinement.hpp"
#include "omnivert/calib/track_ids.hpp"

namespace omnivert::calib {

// What the data's check of the bearing noise found and did (CalibrationOptions::noise_check).
struct NoiseCheckReport {
  // The check of the reported estimate (the refinement's when refined, else the filter's),
  // valid when `checked`; its verdict; `applied`: the reported covariance is the checked one
  // (more noise than the model allows, or less where the tracker kept its lines); `ratio`:
  // the overall variance ratio tr(model^-1 checked) / 3 then (1 when not applied).
  bool checked = false;
  bool applied = false;
  NoiseVerdict verdict = NoiseVerdict::kAgrees;
  BatchNoiseCheck check;
  double ratio = 1.0;
  // The check of the filter on its own tracks (split only where its window split them), its
  // verdict, and the filter's variance ratio (1 when not applied).
  BatchNoiseCheck filter_check;
  NoiseVerdict filter_verdict = NoiseVerdict::kAgrees;
  bool filter_applied = false;
  double filter_ratio = 1.0;
  // CalibrationOptions::noise_check.level and lower_level, as used.
  double level = 0.01;
  double lower_level = 0.2;
  // The model's covariances before any check.
  Eigen::Matrix3d filter_model_covariance = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d refinement_model_covariance = Eigen::Matrix3d::Zero();
};

// Each stage's wall time [s].
struct CalibrationTiming {
  double filter = 0.0, refinement = 0.0, observability = 0.0, noise_check = 0.0;
};

// Which estimator produced the answer of a CalibrationResult.
enum class Estimator {
  kFilter,      // the EKF of Sec. 8.2 (with its start-up window)
  kRefinement,  // the batch maximum-likelihood refinement (CalibrationOptions::refinement)
};
// "filter" or "refinement": the `source` of extrinsics.yaml and summary.json.
const char* estimator_name(Estimator e);

struct CalibrationResult {
  // The answer: the refinement's when refined and its covariance exists, else the filter's;
  // `source` says which.
  Extrinsics extrinsics;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  Estimator source = Estimator::kFilter;
  // Refinement only: its covariance came from the Fisher information of the observability
  // analysis (the inverse of the same information) because ceres::Covariance failed.
  bool covariance_from_information = false;
  // The verdict of Sec. 8.1 and the Cramer-Rao bounds of this run.
  ObservabilityReport observability;
  // The estimators: the filter (with its window's association), the refinement (valid when
  // refined, with its splits, joins and rejections).
  FilterResult filter;
  bool refined = false;
  RefinementResult refinement;
  BearingNoise model;  // the bearing noise the models used (CalibrationOptions::noise)
  NoiseCheckReport noise_check;
  CalibrationTiming seconds;

  bool observable() const { return observability.all_determined(); }
  // A few lines: phi, rho, psi with their sigmas (degrees, millimetres), the camera's position
  // and yaw, and the verdict of Sec. 8.1, e.g.
  //   refined estimate: phi 12.345 +- 0.067 deg, rho 201.23 +- 0.45 mm, psi -3.210 +- 0.070 deg
  //   camera in the robot frame: x 196.5 mm, y 43.0 mm, yaw 9.135 deg
  //   phi, rho and psi are determined by this trajectory (...).
  std::string BriefReport() const;
  // Everything, one item a line: the brief report's lines, then the filter's and the
  // refinement's estimates with their model covariances, the bounds, the bearing noise model
  // and the noise check, the wheel check, the association (window, splits, joins, guarded and
  // rejected bearings), the refinement's solver figures, each stage's time and the warnings
  // (result_warnings).
  std::string FullReport() const;
};

// The independent bearing noise [rad] that would do the harm the noise check found:
// bearing_sigma x sqrt(noise.scale) (the sigma its messages advise); NaN when not checked.
double effective_bearing_sigma(const CalibrationResult& result);
// The same for the per-track part (CalibrationOptions::noise.track_bias_sigma): track_bias_sigma x
// sqrt(noise.scale); 0 when the model has none, NaN when not checked.
double effective_track_bias_sigma(const CalibrationResult& result);
// The bearing noise model in words, e.g. "0.025 deg" or "0.018 deg + 0.016 deg per track",
// for sigmas in radians.
std::string bearing_noise_text(double bearing_sigma, double track_bias_sigma);
// The flags that would weight the bearings as the noise check found them, e.g.
// "--bearing-sigma 0.014" or "--bearing-sigma 0.014 --track-bias-sigma 0.012".
std::string noise_check_flags(const CalibrationResult& result);
// The chance of a noise check's side in words: "x0.71 or less has a 20% chance under it"
// for the limit 0.71, side "less", level 0.2.
std::string noise_check_chance(double limit, const char* side, double level);

// Throws InputError on invalid options or input (non-finite values, repeated track ids).
CalibrationResult calibrate(const CalibrationRun& run, const CalibrationOptions& options = {});

// The result of a filter already run over `run` (a CalibrationFilter fed frame by frame as the
// robot drives, then finished): Sec. 8.1 at its estimate, on the bearings it used, as
// calibrate() analyses it; neither refinement nor noise check (both need the whole run as a
// batch). The answer is the filter's.
CalibrationResult result_of_filter(const CalibrationRun& run,
                                   const CalibrationOptions& options,
                                   FilterResult filter);

// What a user should be told about a result (empty when nothing): the filter's gate refused
// more than 20% of the bearings after its start-up window (it has probably diverged, or the
// tracks mix lines), and, when refined, the refinement lies outside the filter's 99.9%
// ellipsoid (squared Mahalanobis distance under the filter's covariance above 16.27,
// chi-square with 3 degrees of freedom): the filter is biased or overconfident on this run,
// and the refinement's answer is the one to trust (seen where tracks slip onto a
// neighbouring line, docs/theory/association.md#slipped-tracks).
// A warning, too, when the wheel check (WheelCheck, at the refinement or at the filter's
// noise check) finds a systematic wheel error, with its size and what to correct.
std::vector<std::string> result_warnings(const CalibrationResult& result);

// The wheel check of a result: the refinement's when refined, else the filter's noise
// check's (not made: ok = false).
const WheelCheck& wheel_check_of(const CalibrationResult& result);

// DIR/extrinsics.yaml (docs/outputs.md): phi, rho, psi, sigma_phi, sigma_rho, sigma_psi, covariance
// (3x3, row-major), x, y, yaw (= phi + psi), T_base_cam (4x4), observable, crlb_phi,
// crlb_rho, crlb_psi (.inf when not determined), plus source (filter / refinement) and
// message. Written to a temporary file and renamed, so a partial file never looks complete.
// Throws InputError when the file cannot be written.
void write_extrinsics_yaml(const std::string& path, const CalibrationResult& result);

// DIR/states.csv: one row per frame, the filter's estimate and sigmas (Fig. 25's data).
void write_states_csv(const std::string& path, const std::vector<FrameEstimate>& history);

}  // namespace omnivert::calib
