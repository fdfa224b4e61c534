#include "omnivert/calib/refinement.hpp"

#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "calib/association.hpp"
#include "calib/batch_problem.hpp"
#include "calib/noise_check.hpp"
#include "calib/refine_steps.hpp"
#include "calib/serial_sparse_algebra.hpp"
#include "calib/warm_start.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::calib {

using namespace internal;

namespace {

ceres::Solver::Options solver_options(const RefinementOptions& refinement) {
  ceres::Solver::Options so;
  // Sparse Cholesky of the whole normal equations: the poses form a chain and each feature
  // ties many poses, so the Schur complement on either is nearly dense (a 252-frame window
  // with 114 tracks: 17.7 s against 40.8 s with SPARSE_SCHUR, the same solution).
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  so.max_num_iterations = refinement.max_iterations;
  so.function_tolerance = 1e-10;
  so.gradient_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  return so;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// One solve of the batch problem, logged at debug level (iterations, cost, time).
void solve_logged(const ceres::Solver::Options& so,
                  Built* b,
                  ceres::Solver::Summary* summary,
                  const char* what) {
  ceres::Solve(so, b->problem.get(), summary);
  spdlog::debug(
      "refinement {}: {} features, {} bearings, {} iterations, cost {:.6g} -> {:.6g}, {:.2f} s",
      what,
      b->features.size(),
      b->num_bearings,
      summary->iterations.size(),
      summary->initial_cost,
      summary->final_cost,
      summary->total_time_in_seconds);
}

// The association loop of the refinement: the decisions under the bearing's whole error
// (`assoc`, association_options), the problem rebuilt as it was first built.
AssociationSetup association_setup(const CalibrationOptions& assoc,
                                   const ceres::Solver::Options& so,
                                   ceres::Solver::Summary* summary) {
  AssociationSetup s;
  s.options = &assoc;
  s.min_bearings = 2;  // two bearings at least determine a feature point
  s.join_pieces = assoc.association.join_pieces;
  s.split = assoc.association;
  s.judge_before_solving = true;
  s.rebuild = [&assoc](const CalibrationRun& run, const BatchPoint& at) {
    return build(run, assoc, at, assoc.refinement.robust);
  };
  s.solve = [&so, summary](Built* b) { solve_logged(so, b, summary, "association"); };
  s.progress = assoc.progress;
  return s;
}

// The decisions of `a` in the result.
void record_association(Association* a, RefinementResult* res) {
  res->merges = a->merges;
  res->splits = a->splits;
  res->num_splits = a->num_splits;
  res->num_rejected = a->num_rejected;
  if (res->num_splits > 0)
    res->solved_run = std::move(a->split);
  else if (!res->merges.empty())
    res->solved_run = std::move(a->merged);
}

// Scale of the bearing residuals at the solution, in radians (their scatter is the bearing
// noise the data really has: calibrate() can estimate the bearing sigma from it). Robust
// scale (1.4826 x median |r|: false matches left inside the gate do not inflate it),
// corrected for the parameters fitted (2 per feature, 3 extrinsics). Infinity without
// redundancy.
double bearing_residual_sigma(const Built& b, int num_features, double bearing_sigma) {
  std::vector<double> a;
  a.reserve(b.bearing_blocks.size());
  for (ceres::ResidualBlockId id : b.bearing_blocks) {
    double r = 0.0, cost = 0.0;
    b.problem->EvaluateResidualBlock(id, /*apply_loss_function=*/false, &cost, &r, nullptr);
    a.push_back(std::abs(r));
  }
  const int dof = b.num_bearings - 2 * num_features - 3;
  if (dof <= 0 || a.empty()) return std::numeric_limits<double>::infinity();
  std::nth_element(a.begin(), a.begin() + a.size() / 2, a.end());
  const double mad = 1.4826 * a[a.size() / 2];
  return mad * std::sqrt(static_cast<double>(a.size()) / dof) * bearing_sigma;
}

// (phi, rho, psi) and (phi + pi, -rho, psi - pi) place the camera identically (eq. 16-17):
// the solver may end on the second (from a start far from the truth). The answer is given
// with rho >= 0 and the angles wrapped.
void canonical_extrinsics(Built* b) {
  if (b->ex[1] < 0.0) {
    b->ex[0] += kPi;
    b->ex[1] = -b->ex[1];
    b->ex[2] -= kPi;
  }
  b->ex[0] = wrap_angle(b->ex[0]);
  b->ex[2] = wrap_angle(b->ex[2]);
}

// The problem of `b` again, its parameter blocks in one array in a fixed order (poses, the
// extrinsics, features and biases by track id), the cost and loss functions shared.
// ceres::Covariance orders the Jacobian's columns by the parameter blocks' addresses, and
// SuiteSparseQR's ordering and rounding follow that order: with the features in map nodes,
// where the heap put them moved the covariance's last digits from run to run.
struct OrderedCopy {
  std::vector<double> values;
  std::unique_ptr<ceres::Problem> problem;
  const double* ex = nullptr;
  const double* time_offset = nullptr;  // when estimated
};

OrderedCopy ordered_copy(const Built& b) {
  std::vector<double*> order;
  for (const auto& p : b.poses) order.push_back(const_cast<double*>(p.data()));
  order.push_back(const_cast<double*>(b.ex.data()));
  if (!b.time_offset.empty()) order.push_back(const_cast<double*>(b.time_offset.data()));
  for (const auto& [id, f] : b.features) order.push_back(const_cast<double*>(f.data()));
  for (const auto& [id, v] : b.biases) order.push_back(const_cast<double*>(&v));
  OrderedCopy c;
  std::map<const double*, double*> moved;
  std::vector<int> sizes;
  std::size_t total = 0;
  for (double* block : order) {
    sizes.push_back(b.problem->HasParameterBlock(block) ? b.problem->ParameterBlockSize(block) : 0);
    total += static_cast<std::size_t>(sizes.back());
  }
  c.values.resize(total);
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  c.problem = std::make_unique<ceres::Problem>(po);
  std::size_t at = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (sizes[i] == 0) continue;
    double* to = c.values.data() + at;
    std::copy(order[i], order[i] + sizes[i], to);
    c.problem->AddParameterBlock(to, sizes[i]);
    if (b.problem->IsParameterBlockConstant(order[i])) c.problem->SetParameterBlockConstant(to);
    moved[order[i]] = to;
    at += static_cast<std::size_t>(sizes[i]);
  }
  c.ex = moved.at(b.ex.data());
  if (!b.time_offset.empty()) c.time_offset = moved.at(b.time_offset.data());
  std::vector<ceres::ResidualBlockId> blocks;
  b.problem->GetResidualBlocks(&blocks);
  for (ceres::ResidualBlockId id : blocks) {
    std::vector<double*> params;
    b.problem->GetParameterBlocksForResidualBlock(id, &params);
    for (double*& p : params) p = moved.at(p);
    c.problem->AddResidualBlock(
        const_cast<ceres::CostFunction*>(b.problem->GetCostFunctionForResidualBlock(id)),
        const_cast<ceres::LossFunction*>(b.problem->GetLossFunctionForResidualBlock(id)),
        params);
  }
  return c;
}

// Covariance of (phi, rho, psi): the inverse of the Fisher information at the solution (of
// the problem without robust loss, as it is the Gaussian model's bound), marginal; with the
// time offset's correction estimated, its variance too. false when the problem is rank
// deficient (the caller then falls back on the observability analysis).
bool extrinsics_covariance(Built* b, Eigen::Matrix3d* covariance, double* time_offset_variance) {
  ceres::Covariance::Options co;
  // Sparse QR: fails on a rank-deficient problem. DENSE_SVD gives the same covariance to 13
  // digits but takes 100 times longer on 1440 variables (15 s against 0.15 s).
  co.algorithm_type = ceres::SPARSE_QR;
  co.min_reciprocal_condition_number = 1e-14;
  co.null_space_rank = 0;
  co.num_threads = 1;
  ceres::Covariance cov(co);
  const OrderedCopy copy = ordered_copy(*b);
  std::vector<std::pair<const double*, const double*>> blocks = {{copy.ex, copy.ex}};
  if (copy.time_offset) blocks.emplace_back(copy.time_offset, copy.time_offset);
  // A rank-deficient problem is an expected outcome here (the caller falls back on the
  // observability analysis). ceres::Covariance has no logging option: its line about the
  // rank deficiency goes to Ceres' log, which the library leaves as the program set it.
  if (!cov.Compute(blocks, copy.problem.get())) return false;
  double C[9];
  cov.GetCovarianceBlock(copy.ex, copy.ex, C);
  *covariance = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(C);
  if (copy.time_offset)
    cov.GetCovarianceBlock(copy.time_offset, copy.time_offset, time_offset_variance);
  return true;
}

}  // namespace

RefinementResult refine_batch(const CalibrationRun& run,
                              const CalibrationOptions& options,
                              const BatchPoint& start) {
  return internal::refine_batch(run, options, start, RefineSteps{});
}

RefinementResult internal::refine_batch(const CalibrationRun& run,
                                        const CalibrationOptions& options,
                                        const BatchPoint& start,
                                        const RefineSteps& steps) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("calibration options: " + why);
  const SerialSparseAlgebra serial;  // this call's solves: one OpenMP thread in CHOLMOD
  // The decisions under the bearing's whole error; the bias, when modelled, at the end
  // (association_options).
  const CalibrationOptions& model = options;
  const CalibrationOptions assoc = association_options(model);
  Built b = build(run, assoc, warm_start(run, assoc, start), options.refinement.robust);
  RefinementResult res;
  res.num_bearings = b.num_bearings;

  const ceres::Solver::Options so = solver_options(options.refinement);
  ceres::Solver::Options loose = so;
  loose.function_tolerance = options.refinement.association_function_tolerance;
  ceres::Solver::Summary summary;
  if (options.progress) options.progress("refinement: first solve", 0, 0);
  solve_logged(loose, &b, &summary, "first solve");
  // Lines that cross, outliers (false matches, at the filter's gate), pieces of one line,
  // slipped tracks; the problem solved again after each decision.
  Association association;
  associate(&b, run, association_setup(assoc, loose, &summary), &association);
  record_association(&association, &res);
  // The last solve, to the full tolerance; with the track biases when modelled.
  const bool biased = model.noise.track_bias_sigma > 0.0;
  if (biased)
    b = final_with_bias(
        res.renamed() ? res.solved_run : run, b, model, options.refinement.robust, 2);
  solve_logged(so, &b, &summary, biased ? "with the track biases" : "last");
  res.guarded = b.guarded;
  res.rejected =
      unused_bearings(res.renamed() ? res.solved_run : run, b, [](int id) { return id; });
  res.num_bearings = b.num_bearings;
  res.num_features = static_cast<int>(b.features.size());
  res.bearing_residual_sigma =
      bearing_residual_sigma(b, res.num_features, options.noise.bearing_sigma);
  const auto t_check = std::chrono::steady_clock::now();
  res.noise = noise_check(b, options.noise_check);
  res.noise.wheels = wheel_check(b, run, options);
  spdlog::debug("refinement noise check: {:.2f} s", seconds_since(t_check));
  res.converged = summary.termination_type == ceres::CONVERGENCE;
  res.initial_cost = summary.initial_cost;
  res.final_cost = summary.final_cost;
  res.iterations = static_cast<int>(summary.iterations.size());
  res.report = summary.BriefReport();
  canonical_extrinsics(&b);  // and the covariance below is computed there
  res.solution = point_of(b);
  res.extrinsics = res.solution.extrinsics;
  double time_offset_variance = std::numeric_limits<double>::quiet_NaN();
  if (steps.covariance) {
    if (options.progress) options.progress("refinement: covariance", 0, 0);
    const auto t_covariance = std::chrono::steady_clock::now();
    const bool covariance = extrinsics_covariance(&b, &res.covariance, &time_offset_variance);
    spdlog::debug("refinement covariance: {:.2f} s", seconds_since(t_covariance));
    if (covariance) res.covariance_ok = res.covariance.allFinite();
    if (!res.covariance_ok && !b.time_offset.empty() &&
        marginal_with_time_offset(&b, &res.covariance, &time_offset_variance)) {
      res.covariance_ok = true;
      res.covariance_from_information = true;
    }
  }
  if (!b.time_offset.empty()) {
    res.time_offset_estimated = true;
    res.time_offset_s = b.time_offset[0];
    res.time_offset_sigma_s = std::sqrt(time_offset_variance);
  }
  return res;
}

}  // namespace omnivert::calib
