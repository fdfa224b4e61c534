#include "omnivert/calib/refinement.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "calib/association.hpp"
#include "calib/batch_problem.hpp"
#include "calib/noise_check.hpp"
#include "omnivert/calib/updater.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::calib {

using namespace internal;

RefinementResult refine_batch(const CalibrationRun& run,
                              const Options& options,
                              const BatchPoint& start,
                              const BatchOptions& batch) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("calibration options: " + why);
  // The decisions under the bearing's whole error; the bias, when modelled, at the end
  // (association_options).
  const Options& model = options;
  const Options assoc = association_options(model);
  Built b = build(run, assoc, start, batch, batch.robust);
  RefinementResult res;
  res.num_bearings = b.num_bearings;

  ceres::Solver::Options so;
  // Sparse Cholesky of the whole normal equations: the poses form a chain and each feature
  // ties many poses, so the Schur complement on either is nearly dense. Hall zigzag, 252
  // frames and 114 tracks in the filter's window: 17.7 s against 40.8 s with SPARSE_SCHUR,
  // the same solution.
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  so.max_num_iterations = batch.max_iterations;
  so.function_tolerance = 1e-10;
  so.gradient_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, b.problem.get(), &summary);
  // Outlying bearings (false matches) out, at the filter's gate, then solve again.
  const double gate = std::sqrt(chi2_quantile(options.gate_probability, 1));
  std::map<int, int> origin;  // id given by a split -> the tracker's id
  auto reject_and_solve = [&] {
    // Bearings where lines cross out first (the outliers are judged without them).
    if (reject_crossings(&b,
                         options.crossing_guard,
                         options.max_missed_frames,
                         2,
                         origin,
                         chi2_quantile(options.gate_probability, 2)) > 0)
      ceres::Solve(so, b.problem.get(), &summary);
    res.num_rejected = 0;
    if (drop_collapsed_features(&b, options.min_feature_range) > 0)
      ceres::Solve(so, b.problem.get(), &summary);
    for (int round = 0; round < 3; ++round) {
      // Two bearings at least determine a feature point.
      const int n = reject_outliers(&b, gate, 2);
      res.num_rejected += n;
      if (n == 0) break;
      ceres::Solve(so, b.problem.get(), &summary);
    }
  };
  reject_and_solve();
  // Pieces of one line joined (the tracker lost the line and found it again under a new
  // id), and the problem built and solved again, each line starting at its first piece's
  // point.
  CalibrationRun merged = run;
  for (int round = 0; batch.merge_pieces && round < kMergeRounds; ++round) {
    BatchPoint at;
    if (!merge_round(&b, assoc, &merged, &at, &res.merges)) break;
    b = build(merged, assoc, at, batch, batch.robust);
    ceres::Solve(so, b.problem.get(), &summary);
    reject_and_solve();
  }
  // Tracks that slipped onto a neighbouring line are split in two and the problem is built
  // and solved again from the current solution (all bearings back in, outliers re-judged).
  CalibrationRun split_run;
  for (int round = 0; batch.split_chi2 > 0.0 && round < batch.split_rounds; ++round) {
    const std::map<int, int> found = find_splits(b, batch);
    if (found.empty()) break;
    BatchPoint at = point_of(b);
    split_run =
        split_round(merged, round == 0 ? merged : split_run, found, &res.splits, &origin, &at);
    res.num_splits += static_cast<int>(found.size());
    b = build(split_run, assoc, at, batch, batch.robust);
    ceres::Solve(so, b.problem.get(), &summary);
    reject_and_solve();
  }
  if (res.num_splits > 0)
    res.solved_run = std::move(split_run);
  else if (!res.merges.empty())
    res.solved_run = std::move(merged);
  if (model.track_bias_sigma > 0.0) {
    b = final_with_bias(res.renamed() ? res.solved_run : run, b, model, batch, batch.robust, 2);
    ceres::Solve(so, b.problem.get(), &summary);
  }
  res.guarded = b.guarded;
  res.rejected =
      unused_bearings(res.renamed() ? res.solved_run : run, b, [](int id) { return id; });
  res.num_bearings = b.num_bearings;
  res.num_features = static_cast<int>(b.features.size());
  {
    // Bearing residuals at the solution, in radians (their scatter is the bearing noise the
    // data really has: calibrate() can estimate the bearing sigma from it).
    // Robust scale (1.4826 x median |r|: false matches left inside the gate do not inflate
    // it), corrected for the parameters fitted (2 per feature, 3 extrinsics).
    std::vector<double> a;
    a.reserve(b.bearing_blocks.size());
    for (ceres::ResidualBlockId id : b.bearing_blocks) {
      double r = 0.0, cost = 0.0;
      b.problem->EvaluateResidualBlock(id, /*apply_loss_function=*/false, &cost, &r, nullptr);
      a.push_back(std::abs(r));
    }
    const int dof = b.num_bearings - 2 * res.num_features - 3;
    if (dof > 0 && !a.empty()) {
      std::nth_element(a.begin(), a.begin() + a.size() / 2, a.end());
      const double mad = 1.4826 * a[a.size() / 2];
      res.bearing_residual_sigma =
          mad * std::sqrt(static_cast<double>(a.size()) / dof) * options.bearing_sigma;
    }
  }
  res.noise = noise_check(b, batch.noise_check_dense_limit);
  res.noise.wheels = wheel_check(b, run, options, batch);
  res.converged = summary.termination_type == ceres::CONVERGENCE;
  res.initial_cost = summary.initial_cost;
  res.final_cost = summary.final_cost;
  res.iterations = static_cast<int>(summary.iterations.size());
  res.report = summary.BriefReport();
  // (phi, rho, psi) and (phi + pi, -rho, psi - pi) place the camera identically (eq. 16-17):
  // the solver may end on the second (seen from pixels, a start far from the truth); the
  // answer is given with rho >= 0 and the angles wrapped, and the covariance below is
  // computed there.
  if (b.ex[1] < 0.0) {
    b.ex[0] += kPi;
    b.ex[1] = -b.ex[1];
    b.ex[2] -= kPi;
  }
  b.ex[0] = wrap_angle(b.ex[0]);
  b.ex[2] = wrap_angle(b.ex[2]);
  res.solution = point_of(b);
  res.extrinsics = res.solution.extrinsics;

  // Covariance of (phi, rho, psi): the inverse of the Fisher information at the solution
  // (of the problem without robust loss, as it is the Gaussian model's bound), marginal.
  ceres::Covariance::Options co;
  // Sparse QR: fails on a rank-deficient problem (then the caller falls back on the
  // observability analysis). DENSE_SVD gave the same covariance to 13 digits but took 15 s
  // on the hall zigzag (1440 variables) against 0.15 s.
  co.algorithm_type = ceres::SPARSE_QR;
  co.min_reciprocal_condition_number = 1e-14;
  co.null_space_rank = 0;
  co.num_threads = 1;
  ceres::Covariance cov(co);
  std::vector<std::pair<const double*, const double*>> blocks = {{b.ex.data(), b.ex.data()}};
  // A rank-deficient problem is an expected outcome here (the caller falls back on the
  // observability analysis), not an error for the user's terminal: Ceres' own log line
  // ("Covariance matrix is near rank deficient ...") is silenced for this call.
  const int saved_min_log_level = FLAGS_minloglevel;
  FLAGS_minloglevel = google::GLOG_FATAL;
  const bool cov_ok = cov.Compute(blocks, b.problem.get());
  FLAGS_minloglevel = saved_min_log_level;
  if (cov_ok) {
    double C[9];
    cov.GetCovarianceBlock(b.ex.data(), b.ex.data(), C);
    res.covariance = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(C);
    res.covariance_ok = res.covariance.allFinite();
  }
  return res;
}

}  // namespace omnivert::calib
