#pragma once
// The batch problem built in Ceres (batch_point.hpp's formulation) and the edits the
// estimators make to it: bearings and features removed, its Jacobian and information.

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <map>
#include <memory>
#include <set>
#include <utility>
#include <vector>

#include "calib/batch_point.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib::internal {

// The problem with its parameter storage.
struct Built {
  std::vector<std::array<double, 3>> poses;
  std::map<int, std::array<double, 2>> features;
  std::map<int, double>
      biases;  // CalibrationOptions::noise.track_bias_sigma (std::map: stable addresses)
  std::map<int, ceres::ResidualBlockId> bias_priors;  // their priors, by track
  // (phi, rho, psi); heap storage: moving a Built keeps the address Ceres holds.
  std::vector<double> ex = std::vector<double>(3, 0.0);
  // The time offset's correction dS (RefinementOptions::estimate_time_offset): one value when
  // estimated, else empty; heap storage like ex.
  std::vector<double> time_offset;
  std::unique_ptr<ceres::Problem> problem;
  int num_bearings = 0;
  std::vector<ceres::ResidualBlockId> bearing_blocks;
  std::vector<BearingKey> bearing_keys;  // (track id, frame) of each bearing block
  std::vector<ceres::ResidualBlockId> odometry_blocks;
  std::vector<BearingKey> guarded;  // (track id, frame) left out by reject_crossings
};

// Keeps the bearings for which keep(block, (track id, frame)) is true; the others leave the
// problem's bookkeeping (the caller removes their residual blocks, or their parameter block).
// Returns how many left.
template <typename Keep>
int filter_bearings(Built* b, Keep keep) {
  std::vector<ceres::ResidualBlockId> kept;
  std::vector<BearingKey> kept_keys;
  for (std::size_t i = 0; i < b->bearing_blocks.size(); ++i) {
    if (!keep(b->bearing_blocks[i], b->bearing_keys[i])) continue;
    kept.push_back(b->bearing_blocks[i]);
    kept_keys.push_back(b->bearing_keys[i]);
  }
  const int n = static_cast<int>(b->bearing_blocks.size() - kept.size());
  b->num_bearings -= n;
  b->bearing_blocks = std::move(kept);
  b->bearing_keys = std::move(kept_keys);
  return n;
}

// Removes the given features with their bearings and any prior on them. Returns how many.
int remove_features(Built* b, const std::set<int>& drop);

// The bearings of `run` that the solved problem `b` neither uses nor guarded (outliers, and
// those of features removed), as (track id of `run`, frame); `to_run` maps the problem's
// track ids to `run`'s (renamed parts of a track).
template <typename ToRun>
std::vector<BearingKey> unused_bearings(const CalibrationRun& run, const Built& b, ToRun to_run) {
  std::set<BearingKey> out;
  for (std::size_t k = 0; k < run.frames.size(); ++k)
    for (const BearingObservation& o : run.frames[k].observations)
      out.insert({o.track_id, static_cast<int>(k)});
  for (const auto& [id, k] : b.bearing_keys) out.erase({to_run(id), k});
  for (const auto& [id, k] : b.guarded) out.erase({to_run(id), k});
  return {out.begin(), out.end()};
}

// Removes the features left with fewer than `min_bearings` bearings (with their remaining
// bearings and any prior on them): their information is singular. A track whose bearings are
// all outliers in the filter's window would leave the window's information singular, and the
// filter would fall back on the undelayed initialisation
// (CalibrationFilter.BootstrapWindowDropsATrackWithOnlyOutliers; docs/theory/window.md).
// Returns how many features.
int drop_unobserved_features(Built* b, int min_bearings);

// Removes the features that the solution puts closer than `min_range` to the camera centre
// (eq. 16-17) at a frame with one of their bearings
// (CalibrationOptions::association.min_feature_range), with their bearings and any prior on them.
// Returns how many features.
int drop_collapsed_features(Built* b, double min_range);

// Removes the bearings whose whitened residual exceeds `threshold` (the filter's chi-square
// gate, in sigmas) at the current solution, then the features left with fewer than
// `min_bearings` bearings (drop_unobserved_features). Returns how many bearings.
int reject_outliers(Built* b, double threshold, int min_bearings);

// F = J^T J with a tiny ridge, relative to each variable's own information (their scales
// differ by orders of magnitude): it keeps a feature seen without parallax from making F
// singular. A variable without any residual left (a feature whose bearings were all removed
// as outliers) has an empty row and column; a unit diagonal leaves it
// out of everything else.
Eigen::SparseMatrix<double> information_with_ridge(const Eigen::SparseMatrix<double>& J);

// A Jacobian in Ceres' compressed-row form as an Eigen sparse matrix (rows x cols).
Eigen::SparseMatrix<double> sparse_jacobian(const ceres::CRSMatrix& crs);

// The Jacobian of b's residuals (without the loss function) in the columns of
// variable_blocks(b). Ceres' compressed rows are freed before it returns: on a long run each
// form is tens of MB. false when Ceres cannot evaluate the problem.
bool whole_jacobian(Built& b, Eigen::SparseMatrix<double>* J);

// J^T J of a Jacobian in Ceres' compressed-row form, as a dense matrix. Each row of J has a
// handful of entries (a bearing touches one pose, one feature and the extrinsics), so the
// product is formed sparse: O(rows x 8^2) instead of the dense O(rows x cols^2) (318 tracks:
// the filter's window 12.97 -> 8.44 s, the observability analysis 2.62 -> 0.68 s).
Eigen::MatrixXd information_from_jacobian(const ceres::CRSMatrix& crs);

// The variables of the batch problem in the order of its Jacobian's columns: poses of frames
// 1..N (frame 0 is the gauge), features, track biases, extrinsics (the last three columns).
std::vector<double*> variable_blocks(Built& b);

// The problem of `run` at `at` (the formulation of batch_point.hpp): a pose per frame (frame
// 0 constant, the gauge), the extrinsics, a point per track with at least
// options.association.min_track_length bearings and a finite starting point, and with
// options.noise.track_bias_sigma a bias per track with its prior; odometry factors between
// consecutive frames (eq. 14-15, 31, with robot.lateral_sigma), a bearing factor per
// observation (eq. 16-17, Huber loss when `robust`). Throws InputError when `at` has not one
// pose per frame.
Built build(const CalibrationRun& run,
            const CalibrationOptions& options,
            const BatchPoint& at,
            bool robust);

// The solver of the small problems solved on the side (a window of the warm start, the placed
// points of the association's renamed tracks): sparse normal Cholesky, at most 50 iterations,
// Ceres' default function tolerance (1e-6), one thread, silent.
ceres::Solver::Options small_solver_options();

// The problem's current values, angles wrapped.
BatchPoint point_of(const Built& b);

// With the time offset's correction estimated (Built::time_offset): the marginal covariance
// of (phi, rho, psi) and the correction's variance from the Fisher information J^T J at the
// current values (no robust loss), by one sparse LDLT factorisation.
// false when the factorisation fails or a variance is not positive.
bool marginal_with_time_offset(Built* b, Eigen::Matrix3d* covariance, double* time_offset_variance);

}  // namespace omnivert::calib::internal
