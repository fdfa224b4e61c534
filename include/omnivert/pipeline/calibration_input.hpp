#pragma once
// From a recorded dataset and its tracks to the calibration's input (what `omnivert
// calibrate` does between tracking and the filter of Sec. 8.2):
//   - per image, the wheel travels since the previous image (eq. 14-15's inputs), from the
//     cumulative travel interpolated at the image timestamps (dataset::Dataset);
//   - per image, the bearings of its tracked lines {track_id, beta}.
//
// Checks that turn bad recordings into warnings (each naming the file and lines):
//   - a gap in the wheel data around an image (no wheel sample within `max_wheel_gap_s` on
//     one side): the robot's pose at that image is not known, only the travel across the gap,
//     so the image's bearings are dropped (the travel is kept: it sums correctly);
//   - a track holding two lines of one frame (the paper's rules allow it): both bearings are
//     dropped for that frame (which line is the track's is ambiguous);
//   - long stretches with fewer than `min_lines` tracked lines ("too few lines for too
//     long"): the filter dead-reckons through them; reported with their frames and duration.
// A run in which no frame has `min_lines` lines is an InputError.

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "omnivert/calib/options.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/match/tracks_io.hpp"

namespace omnivert::pipeline {

struct DatasetRunOptions {
  double max_wheel_gap_s = 0.5;  // a wheel sample interval longer than this is a gap [s]
  int min_lines = 2;             // fewer tracked lines than this in a frame: starved
  double max_starved_s = 10.0;   // a starved stretch longer than this is warned about [s]
  // Shorter tracks carry no parallax: left out of the input (the batch problems have their
  // own, larger, calib::AssociationOptions::min_track_length).
  int min_track_length = 2;
  // A crowded line's bearing (TrackRow::crowded: another edge within a few pixels all along
  // it) has its sigma multiplied by this (BearingObservation::sigma_scale).
  double crowded_sigma_scale = 1.0;
  // The bearings of lines shorter than this fraction of the annulus (TrackRow::
  // annulus_fraction, R_max - R_min) are tracked but not used: the shorter a line, the
  // larger the part of its bearing error that stays the same from frame to frame, which the
  // filter's sigma does not model (docs/theory/extraction.md#significance). 0.5 is the
  // paper's rule (Sec. 2); 0 uses every bearing. A row whose fraction is not known is used.
  double min_annulus_fraction = 0.5;
  // When fewer tracks than this hold two such lines, the bearings of shorter lines are used:
  // those at least 0.35, 0.25 of the annulus, then every one, the first that gives this many
  // tracks (with a warning; DatasetRun::min_annulus_fraction is the fraction used). 0: never.
  int enough_tracks = 15;
  // The bearing sigma of a line used that way (shorter than min_annulus_fraction) is
  // multiplied by this (BearingObservation::sigma_scale).
  double short_sigma_scale = 2.0;
  // Where a track's line was shorter than the fraction for at least this many frames and
  // is long again, the rest of the track is a new track for the calibration (the tracker may
  // have slipped onto another edge meanwhile). 0: never.
  int split_after_short = 3;

  // True when every field is usable; otherwise false with the reason in *why (may be null),
  // naming the field, e.g. "max_wheel_gap_s must be > 0 [s]".
  bool IsValid(std::string* why) const;
};

struct DatasetRun {
  calib::CalibrationRun run;
  std::vector<std::string> warnings;
  int frames_dropped_for_gaps = 0;    // frames whose bearings were dropped (wheel gap)
  int double_claims = 0;              // (frame, track) pairs dropped
  int crowded_bearings = 0;           // bearings of crowded lines used
  int short_bearings = 0;             // bearings left out: line below min_annulus_fraction
  double min_annulus_fraction = 0.0;  // that fraction (DatasetRunOptions)
  int split_after_short = 0;          // DatasetRunOptions::split_after_short
  double crowded_sigma_scale = 1.0;   // their sigma scale (DatasetRunOptions)
  int starved_frames = 0;             // frames with fewer than min_lines lines
  int tracks = 0;                     // tracks used
  int observations = 0;               // bearings used
  double path_length = 0.0;           // distance driven by the axle midpoint [m]
  double rotation = 0.0;              // total |heading change| [rad]
};

// `rows` are tracks.csv rows of this dataset (frame = index into data.images()). The dataset
// must have wheel data (InputError otherwise, naming wheel0/).
DatasetRun calibration_run_from_tracks(const dataset::Dataset& data,
                                       const std::vector<TrackRow>& rows,
                                       const DatasetRunOptions& options = {});

// The cumulative wheel travel (left, right) [m] from image i - 1 to image i, on the odometry
// clock: the travel at image i - 1, every wheel sample between, the travel at image i (the
// input of calib::compose_wheel_steps). 1 <= i < data.size(); the dataset has wheel data.
std::vector<Eigen::Vector2d> wheel_travel_between_images(const dataset::Dataset& data,
                                                         std::size_t i);

// The wheels' cumulative travel and the image stamps on the odometry clock (with the dataset's
// time offset applied), in seconds from the first wheel sample: what the refinement estimates
// a correction of the time offset from (calib::RefinementOptions::estimate_time_offset).
std::shared_ptr<const calib::WheelClock> wheel_clock(const dataset::Dataset& data);

// CalibrationOptions filled from the dataset: wheel base from wheel0/sensor.yaml, Chong-Kleeman K
// from its odometry_k when given (else the default of CalibrationOptions), the rest from `base`.
calib::CalibrationOptions options_from_dataset(const dataset::Dataset& data,
                                               calib::CalibrationOptions base = {});

}  // namespace omnivert::pipeline
