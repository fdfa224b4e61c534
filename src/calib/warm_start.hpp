#pragma once
// The refinement's starting trajectory for a long run (docs/theory/refinement.md#long-runs).
//
// The batch starts from dead-reckoned poses (eq. 14) and the filter's features, each placed in
// the world from the pose of its last frame. Over a long run dead reckoning drifts: on the
// simulator's 90 m hall tour its heading is off by several degrees by the end, so most
// bearings of the lines seen all along start hundreds of sigmas off, and the whole-run solve
// spends most of its iterations bending the trajectory back. Solved window by window instead,
// each window from the end of the one before, with the extrinsics held, the drift is taken
// out where it arises; each window is small and starts near its answer, and the whole-run
// solve then starts near its own.

#include "omnivert/calib/options.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib::internal {

// `start` with its poses and features re-solved window by window over the run
// (RefinementOptions::warm_start_window frames each, overlapping by warm_start_overlap; the
// first pose of each window held, the extrinsics held, Huber loss on the bearings), the poses
// and features after each window moved by the rigid motion that took its last pose from the
// start to its solution. `start` unchanged when the run is shorter than two windows or the
// warm start is off (window 0).
BatchPoint warm_start(const CalibrationRun& run,
                      const CalibrationOptions& options,
                      const BatchPoint& start);

}  // namespace omnivert::calib::internal
