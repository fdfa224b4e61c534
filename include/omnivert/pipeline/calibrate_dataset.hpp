#pragma once
// The main job as one library call: a dataset folder in, the camera-to-odometry extrinsics
// and every output file out. `omnivert calibrate` is a thin layer over it.
//
//   1. the lines of every image tracked (paper Sec. 2-4, 9.1), or an earlier tracks.csv read;
//   2. the calibration's input: bearings per track and frame, wheel increments (eq. 14-15);
//   3. the filter (Sec. 8.2), observability (Sec. 8.1), the optional refinement and the checks
//      (calib::calibrate);
//   4. the outputs, each written atomically into `out_dir`: tracks.csv, tracks.png, states.csv,
//      convergence.png (Fig. 25), summary.json, report.html, and extrinsics.yaml when the run
//      determines the extrinsics (or `force`), and with it the same estimate as a URDF joint,
//      static_transform_publisher lines and a Kalibr-style YAML (calib/robot_formats.hpp).
//      docs/outputs.md describes every field.
//
// Bad input (a missing or malformed dataset, tracks of another dataset, invalid options)
// throws InputError naming the file, line and problem; nothing of an earlier run is left in
// `out_dir` to pass for this run's.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "omnivert/calib/calibrate.hpp"
#include "omnivert/calib/robot_formats.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/match/tracker.hpp"
#include "omnivert/pipeline/calibration_input.hpp"
#include "omnivert/pipeline/reprojection.hpp"
#include "omnivert/pipeline/time_offset.hpp"
#include "omnivert/pipeline/track_dataset.hpp"

namespace omnivert::pipeline {

struct CalibrateDatasetOptions {
  FeaturePipelineOptions features;  // extraction and descriptor (Sec. 2-3)
  // Image mask file used instead of the `mask:` of cam0/sensor.yaml; empty: that one, if any.
  std::string mask;
  // The tracker; its odometry gate takes the wheel base of wheel0/sensor.yaml.
  TrackerOptions tracker = recommended_dataset_tracker_options();
  // The estimator's options: prior, models, filter, refinement, noise check. The wheel base and
  // Chong-Kleeman K come from wheel0/sensor.yaml (options_from_dataset); everything else
  // from here.
  calib::CalibrationOptions calibration = calib::recommended_options();
  DatasetRunOptions input;  // wheel gaps, crowded lines
  std::string tracks_file;  // non-empty: calibrate from this earlier tracks.csv
  bool force = false;       // write extrinsics.yaml even when undetermined
  std::string command;      // the command line, recorded in the report
  // What the report names as the input (a recording and its imported dataset); empty: the
  // dataset folder.
  std::string input_name;
  // Where the prior of `calibration` came from, named in the report; empty: the defaults.
  std::string prior_source;
  std::vector<std::string> notes;  // extra warnings of the caller, reported with the rest
  TiltCheckOptions tilt;           // the tilt of the mirror axis (pipeline/tilt_check.hpp)
  int threads = 0;  // threads of the frame pipeline (TrackDatasetOptions) and the estimators
  // The causal mode of a robot that calibrates as it drives (pipeline/streaming.hpp): each
  // image through extraction, tracker and filter in turn on one thread, the estimate after
  // each written to streaming.csv with the time the frame took. The answer is the filter's;
  // no refinement, no noise check, no time-offset estimate (each needs the whole run), and
  // the images themselves (no tracks_file).
  bool streaming = false;
  // Frame names and camera height of the robot-format files written with extrinsics.yaml
  // (calib/robot_formats.hpp).
  calib::RobotFrames frames;
  // The camera-odometry time offset [s], positive when the image stamps are late: given (the
  // stamps shifted before tracking), or empty: estimated from the tracks and, when significant,
  // applied and the images tracked again on the corrected stamps; with the refinement,
  // estimated again with the extrinsics and, when its correction is significant, applied and
  // the run tracked and calibrated again, once (pipeline/time_offset.hpp, docs/calibration.md).
  std::optional<double> time_offset_s;
  TimeOffsetOptions time_offset;
  // The check by eye (pipeline/reprojection.hpp), written as reprojection.png: against
  // `reprojection.reference` when check_reference is set (bad references are then bad input),
  // else against laser0/ when the dataset has it (a bad laser0/ is then a warning); none with
  // check_off. Its gate and frames are those of `reprojection`; its extraction is `features`.
  ReprojectionOptions reprojection;
  bool check_reference = false;
  bool check_off = false;
  // Called while tracking (stage "track", frames done, frames in all; "track again" when an
  // estimated time offset is applied), once before the calibration (stage "calibrate", 0, 0),
  // then with the calibration's stages (calib::CalibrationOptions::progress).
  std::function<void(const std::string& stage, std::size_t done, std::size_t total)> progress;

  // The whole tree at once: features, tracker, calibration, input, tilt, frames, time offset.
  // False with the reason in *why (may be null), which names the group first, e.g.
  // "calibration options: noise.bearing_sigma must be > 0 [rad]". calibrate_dataset throws
  // InputError("invalid " + why) when it is false.
  bool IsValid(std::string* why) const;
};

struct CalibrateDatasetResult {
  calib::CalibrationResult calibration;
  DatasetRun input;  // what the estimator was given
  std::int64_t frames = 0, frames_skipped = 0, detections = 0;
  std::optional<calib::Extrinsics> truth;  // ground_truth/extrinsics.yaml, when present
  std::vector<std::string> warnings;       // tracking's, the input's and the estimate's
  bool wrote_extrinsics = false;           // determined, or forced
  std::string out_dir;
  bool noise_check_requested = true;  // CalibrationOptions::noise_check.enabled of the run
  TiltEstimate tilt;                  // measured before tracking (not valid: not measured)
  bool tilt_corrected = false;        // the frames were rectified with tilt.vector
  TimeOffsetEstimate time_offset;     // estimated, or the given one (time_offset_given)
  bool time_offset_given = false, time_offset_applied = false;
  std::string time_offset_message;   // time_offset_line(): the terminal's and the report's line
  std::string reprojection_message;  // the check by eye's line; empty when not made
  std::string streaming_message;     // a streaming run's times per frame; empty otherwise

  // The answer: the refinement's estimate when it ran and its covariance is usable, else the
  // filter's (the same as calibration.extrinsics / calibration.covariance).
  const calib::Extrinsics& extrinsics() const { return calibration.extrinsics; }
  // A few lines for a terminal: counts, the estimate with sigmas, the camera pose, the noise
  // and wheel checks, splits and joins, the Cramer-Rao bound, errors against the truth when
  // known, the observability verdict and where the files are.
  std::string BriefReport() const;
};

// Runs the main job on the dataset folder `dataset_dir`, writing into `out_dir` (created when
// missing). Throws InputError for bad input and std::runtime_error when the estimate is not
// finite (only tracks.csv and tracks.png are then written).
CalibrateDatasetResult calibrate_dataset(const std::string& dataset_dir,
                                         const std::string& out_dir,
                                         const CalibrateDatasetOptions& options = {});

}  // namespace omnivert::pipeline
