#pragma once
// Batch maximum-likelihood refinement of a whole run (Ceres), on the batch formulation of
// docs/theory/refinement.md (unknowns: the BatchPoint of types.hpp).

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "omnivert/calib/diagnostics.hpp"
#include "omnivert/calib/options.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

struct RefinementResult {
  bool converged = false;
  BatchPoint solution;
  Extrinsics extrinsics;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
  bool covariance_ok = false;  // false when the problem is rank deficient (not observable)
  // The covariance is the marginal of the Fisher information at the solution, computed here
  // because ceres::Covariance gave up (with the time offset estimated; see refine_batch).
  bool covariance_from_information = false;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;
  int num_bearings = 0;  // bearings used
  int num_rejected = 0;  // bearings removed as outliers (|residual| > the filter's gate)
  int num_features = 0;  // tracks in the problem (after splitting)
  int num_splits = 0;    // splits made (a track cut at n frames counts n; association.split_chi2)
  // (track id, first frame of the new part): the tracker's id, or with merges the id of the
  // line's first piece.
  std::vector<TrackSplit> splits;
  // Pieces of one line joined (CalibrationOptions::association.join_pieces): (earlier track id,
  // later track id), the later piece's bearings renamed to the line's first piece.
  std::vector<TrackJoin> merges;
  // Bearings left out where lines cross (CalibrationOptions::association.crossing_guard): (track id
  // of the solved run, i.e. of solved_run when tracks were split or merged, frame).
  std::vector<BearingKey> guarded;
  // Bearings removed as outliers (the gate) or with a feature left with too few bearings:
  // (track id of the solved run, frame). With `guarded`, what the solution did not use; the
  // bound of Sec. 8.1 for this run is computed without them (calibrate()).
  std::vector<BearingKey> rejected;
  // With splits or merges (renamed()): the run `solution` refers to (split parts and merged
  // pieces renamed); otherwise empty, and `solution` refers to the run given.
  CalibrationRun solved_run;
  bool renamed() const { return num_splits > 0 || !merges.empty(); }
  // Scale of the bearing residuals at the solution, outliers removed [rad]: 1.4826 x median
  // |residual| x sqrt(bearings / (bearings - 2 features - 3)); the bearing noise the data
  // has (infinity without redundancy).
  double bearing_residual_sigma = std::numeric_limits<double>::infinity();
  BatchNoiseCheck noise;  // at the solution (outliers removed, splits made)
  // The time offset's correction dS [s] and its sigma, estimated with the extrinsics
  // (RefinementOptions::estimate_time_offset and the run's clock); the sigma is the marginal
  // of the same covariance as the extrinsics' (NaN when that failed).
  bool time_offset_estimated = false;
  double time_offset_s = 0.0;
  double time_offset_sigma_s = std::numeric_limits<double>::quiet_NaN();
  std::string report;  // Ceres' brief report
};

// Batch maximum-likelihood refinement over the whole run (Ceres, Levenberg-Marquardt),
// started from `start`, with the covariance of (phi, rho, psi) from ceres::Covariance.
// Bearings whose residual exceeds the filter's chi-square gate
// (options.association.gate_probability) at the solution are removed and the problem solved again
// (up to three rounds).
RefinementResult refine_batch(const CalibrationRun& run,
                              const CalibrationOptions& options,
                              const BatchPoint& start);

}  // namespace omnivert::calib
