#pragma once
// The filter's start-up window (CalibrationFilter): its first frames solved as a batch.

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "omnivert/calib/calibration_filter.hpp"
#include "omnivert/calib/filter_state.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

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
  std::vector<std::pair<int, int>> splits;   // (tracker's track id, window frame of the new part)
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

bool bootstrap_filter_state(const CalibrationRun& window,
                            const Options& options,
                            FilterState* state,
                            std::string* why = nullptr,
                            BootstrapDetails* details = nullptr);

}  // namespace omnivert::calib
