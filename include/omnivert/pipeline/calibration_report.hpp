#pragma once
// What `omnivert calibrate` writes besides extrinsics.yaml and states.csv:
//   convergence.png  the paper's Fig. 25: phi, rho, psi and their sigmas against the frame
//                    number (with the ground truth, when the dataset has it, dashed);
//   summary.json     inputs, verdicts (Sec. 8.1), estimates with sigmas and Cramer-Rao
//                    bounds, and the errors against the ground truth when there is one;
//   report.html      one page: the same, plus the pictures (convergence.png, tracks.png).
// No output contains a NaN: a value that does not exist is null (JSON), "not determined"
// (HTML) or .inf (YAML, an unbounded Cramer-Rao bound).

#include <optional>
#include <string>
#include <vector>

#include "omnivert/calib/calibrate.hpp"
#include "omnivert/extract/tilt_estimator.hpp"
#include "omnivert/pipeline/calibration_input.hpp"

namespace omnivert::pipeline {

// Errors of an estimate against the truth (angles wrapped).
struct ErrorsVsTruth {
  double phi = 0, rho = 0, psi = 0;  // [rad, m, rad]
  double x = 0, y = 0;               // camera position [m]
  double position = 0;               // |(x, y)| [m]
  double yaw = 0;                    // phi + psi [rad]
  double nees = 0;                   // e^T C^-1 e over (phi, rho, psi); inf if C is singular
};
ErrorsVsTruth errors_vs_truth(const calib::Extrinsics& estimate,
                              const Eigen::Matrix3d& covariance,
                              const calib::Extrinsics& truth);

// Everything the report shows, gathered by the caller.
struct ReportInputs {
  std::string dataset;  // the dataset folder (and the recording it was imported from)
  // Where the prior's mean came from (the dataset's prior.yaml of the recording's /tf_static,
  // a --prior file, flags); empty: the defaults.
  std::string prior_source;
  std::string command;      // the command line, for reproduction
  std::int64_t frames = 0;  // images
  std::int64_t frames_skipped = 0;
  std::int64_t detections = 0;
  std::int64_t tracks_total = 0;  // tracks found by the tracker
  const DatasetRun* run = nullptr;
  calib::CalibrationOptions options;
  std::optional<calib::Extrinsics> truth;  // ground_truth/extrinsics.yaml
  bool force = false;
  int exit_code = 0;
  double seconds_tracking = 0, seconds_calibration = 0;
  std::vector<std::string> warnings;  // tracking's and the run's
  bool wrote_extrinsics = false;
  // The camera-odometry time offset (pipeline/time_offset.hpp).
  struct TimeOffset {
    bool given = false;       // --time-offset S, else estimated
    bool determined = false;  // given, or estimated with a usable sigma
    bool applied = false;     // the image stamps were shifted by it
    double offset_s = 0, sigma_s = 0;
    int pairs = 0;
    double residual_scale = 0;
    bool refined = false;  // refined with the extrinsics (TimeOffsetEstimate::refined)
    double tracks_offset_s = 0, tracks_sigma_s = 0;
    std::string line;  // time_offset_line(): the terminal's and the report's words
  } time_offset;
  // The check by eye (pipeline/reprojection.hpp), when made: summary.json's "reprojection"
  // object (JSON text) and report.html's section.
  std::string reprojection_json, reprojection_html;
  // A streaming run (pipeline/streaming.hpp), when it was one: summary.json's "streaming"
  // object (JSON text) and report.html's section.
  std::string streaming_json, streaming_html;
  // The tilt of the mirror axis (pipeline/tilt_check.hpp): measured when tilt.valid, given
  // (--tilt-deg) when the frames were rectified with an estimate that is not valid.
  TiltEstimate tilt;
  bool tilt_rectified = false;
};

// One line on the noise check (docs/theory/noise-check.md), for the terminal and the
// report: over how many tracks, the independent noise the errors act as, and what was done;
// empty when no check was made.
std::string noise_check_line(const calib::CalibrationResult& result);
// One line on the wheel check (WheelCheck): the wheels' turn scale and drift against the
// robot's, and the verdict; empty when no check was made.
std::string wheel_check_line(const calib::CalibrationResult& result);

// summary.json's text (pretty-printed JSON).
std::string summary_json(const calib::CalibrationResult& result, const ReportInputs& inputs);
// report.html's text: refers to convergence.png and tracks.png next to it.
std::string report_html(const calib::CalibrationResult& result, const ReportInputs& inputs);

}  // namespace omnivert::pipeline
