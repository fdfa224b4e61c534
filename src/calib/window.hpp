#pragma once
// The filter's start-up window (CalibrationFilter): its first frames solved as a batch, the
// filter started from that solution. window.cpp solves the window, window_state.cpp carries
// the solution to the filter's state.

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "calib/association.hpp"
#include "calib/batch_problem.hpp"
#include "calib/filter_state.hpp"
#include "omnivert/calib/calibration_filter.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

// Delayed initialisation of the filter (FeatureInit::kAnchoredInverseDepth with
// options.bootstrap_frames > 0): the first frames are solved as a small batch maximum a
// posteriori problem (the prior on phi, rho, psi, an inverse-depth prior N(q0, sigma_q^2)
// along each track's first ray, odometry, bearings; Levenberg-Marquardt relinearises), and
// the filter starts at the last of them from that solution and its covariance (inverse of
// the Fisher information with the priors), carried to the filter's coordinates (camera pose;
// each track as an anchored inverse-depth point anchored at the camera) through central
// differences. This removes the early-update inconsistency of docs/theory/filter.md and
// docs/theory/window.md#why-a-window: one linearisation per frame while depth and camera yaw are
// both unknown. Tracks with fewer than 2 bearings in the window are left out (they enter
// afterwards). Outlying bearings are removed as in refine_batch. Tracks that slipped onto a
// neighbouring line are split as in refine_batch (options.association.split_chi2); the later part
// of such a track enters the state under the tracker's id. Returns false (state untouched, reason
// in *why) when the window cannot be solved.
struct BootstrapDetails {
  // Every track of the window's solution as (D, theta) from the robot at its last window
  // frame (frame = index in the window), with covariance: tracks that ended inside the window
  // never enter the state, and the refinement starts from these. A split track: its latest
  // part.
  std::map<int, TrackEstimate> tracks;
  std::vector<TrackSplit> splits;  // (tracker's track id, window frame of the new part)
  std::vector<BearingKey>
      guarded;  // (tracker's track id, window frame) left out
                // where lines cross (CalibrationOptions::association.crossing_guard)
  // (tracker's track id, window frame) removed as outliers (the gate) or with a feature left
  // without bearings: with `guarded`, what the window's solution did not use.
  std::vector<BearingKey> rejected;
  // Pieces of one line joined in the window (find_merges,
  // CalibrationOptions::association.join_pieces): (tracker's id of an earlier piece, of the piece
  // joined to it). The line's feature is in the state under its first piece's id; the filter takes
  // later bearings of any of its pieces for it.
  std::vector<TrackJoin> joins;
};

bool bootstrap_filter_state(const CalibrationRun& window,
                            const CalibrationOptions& options,
                            FilterState* state,
                            std::string* why = nullptr,
                            BootstrapDetails* details = nullptr);

namespace internal {

// First and last frame and number of bearings of each track of a window (0 for a track it
// does not have).
struct WindowTracks {
  std::map<int, int> first_frame, last_frame, count;
  void index(const CalibrationRun& window);
  int first(int id) const { return value_of(first_frame, id); }
  int last(int id) const { return value_of(last_frame, id); }
  int bearings(int id) const { return value_of(count, id); }

 private:
  static int value_of(const std::map<int, int>& m, int id) {
    const auto it = m.find(id);
    return it != m.end() ? it->second : 0;
  }
};

// The tracker's ids of the solved window's tracks and bearings.
struct WindowIds {
  std::map<int, int> renamed;          // every renamed id -> the tracker's
  std::map<BearingKey, int> bearings;  // (id, window frame) -> the tracker's id
  int tracker_id(int id) const;
  // A joined piece's bearings carry its line's first id in the window, their own in the
  // tracker's run.
  int of_bearing(int id, int frame) const;
};
// `renamed`: tracker_ids of the association; every renaming keeps the order of a frame's
// bearings, so the solved window and the tracker's are read side by side.
WindowIds window_ids(const CalibrationRun& solved,
                     const CalibrationRun& window_in,
                     std::map<int, int> renamed);

// The solved window `b` (W frames, its tracks `tracks`, decided as `association` says) as the
// filter's state at its last frame, and the details. false (reason in *why) when its
// information is singular or the result not finite.
bool window_to_filter(Built& b,
                      const CalibrationOptions& options,
                      int W,
                      const WindowTracks& tracks,
                      const WindowIds& ids,
                      const Association& association,
                      const std::map<int, int>& gap_origin,
                      FilterState* state,
                      BootstrapDetails* details,
                      std::string* why);

}  // namespace internal

}  // namespace omnivert::calib
