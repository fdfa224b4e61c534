#include "calib/batch_problem.hpp"

#include <cmath>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>

#include "calib/batch_factors.hpp"
#include "omnivert/calib/model.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::calib::internal {

int remove_features(Built* b, const std::set<int>& drop) {
  if (drop.empty()) return 0;
  // The bearings first, in the problem's order, then each bias's prior and the points, which
  // have no residual block left: Ceres removes a parameter block's dependents in the order of
  // a hash set of addresses (Problem::Options::enable_fast_removal), which would make the
  // order of the Jacobian's rows, and the last bits of the solution, differ from run to run.
  filter_bearings(b, [&](ceres::ResidualBlockId block, const BearingKey& key) {
    if (!drop.count(key.track)) return true;
    b->problem->RemoveResidualBlock(block);
    return false;
  });
  for (int id : drop) {
    if (auto it = b->biases.find(id); it != b->biases.end()) {
      b->problem->RemoveParameterBlock(&it->second);  // and its prior
      b->biases.erase(it);
      b->bias_priors.erase(id);
    }
    b->problem->RemoveParameterBlock(b->features.at(id).data());  // and any prior on it
    b->features.erase(id);
  }
  return static_cast<int>(drop.size());
}

int drop_unobserved_features(Built* b, int min_bearings) {
  std::map<int, int> count;
  for (const auto& [id, frame] : b->bearing_keys) ++count[id];
  std::set<int> drop;
  for (const auto& [id, f] : b->features)
    if (count[id] < min_bearings) drop.insert(id);
  return remove_features(b, drop);
}

int drop_collapsed_features(Built* b, double min_range) {
  std::set<int> drop;
  for (const auto& [id, k] : b->bearing_keys) {
    const auto& p = b->poses[static_cast<std::size_t>(k)];
    const auto& f = b->features.at(id);
    const double a = p[2] + b->ex[0];
    const double range =
        std::hypot(f[0] - p[0] - b->ex[1] * std::cos(a), f[1] - p[1] - b->ex[1] * std::sin(a));
    if (!(range >= min_range)) drop.insert(id);
  }
  return remove_features(b, drop);
}

int reject_outliers(Built* b, double threshold, int min_bearings) {
  const int n = filter_bearings(b, [&](ceres::ResidualBlockId id, const BearingKey&) {
    double r = 0.0, cost = 0.0;
    b->problem->EvaluateResidualBlock(id, /*apply_loss_function=*/false, &cost, &r, nullptr);
    if (std::abs(r) <= threshold) return true;  // (false for NaN)
    b->problem->RemoveResidualBlock(id);
    return false;
  });
  if (n > 0) drop_unobserved_features(b, min_bearings);
  return n;
}

Eigen::SparseMatrix<double> information_with_ridge(const Eigen::SparseMatrix<double>& J) {
  Eigen::SparseMatrix<double> F = J.transpose() * J;
  for (int i = 0; i < F.rows(); ++i) {
    double& d = F.coeffRef(i, i);
    d = d > 0.0 ? d * (1.0 + 1e-10) : 1.0;
  }
  return F;
}

Eigen::SparseMatrix<double> sparse_jacobian(const ceres::CRSMatrix& crs) {
  // Ceres' compressed rows are a row-major sparse matrix: read in place and transposed into
  // column-major storage in one pass (no triplet list: on a long run that was 16 bytes per
  // non-zero more, and a second copy inside setFromTriplets).
  if (crs.values.empty()) return Eigen::SparseMatrix<double>(crs.num_rows, crs.num_cols);
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>> rows(
      crs.num_rows,
      crs.num_cols,
      static_cast<Eigen::Index>(crs.values.size()),
      crs.rows.data(),
      crs.cols.data(),
      crs.values.data());
  return Eigen::SparseMatrix<double>(rows);
}

bool whole_jacobian(Built& b, Eigen::SparseMatrix<double>* J) {
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = variable_blocks(b);
  eo.apply_loss_function = false;
  ceres::CRSMatrix crs;
  if (!b.problem->Evaluate(eo, nullptr, nullptr, nullptr, &crs)) return false;
  *J = sparse_jacobian(crs);
  return true;
}

Eigen::MatrixXd information_from_jacobian(const ceres::CRSMatrix& crs) {
  const Eigen::SparseMatrix<double> J = sparse_jacobian(crs);
  const Eigen::SparseMatrix<double> F = J.transpose() * J;
  return Eigen::MatrixXd(F);
}

std::vector<double*> variable_blocks(Built& b) {
  std::vector<double*> v;
  for (std::size_t k = 1; k < b.poses.size(); ++k) v.push_back(b.poses[k].data());
  for (auto& [id, f] : b.features) v.push_back(f.data());
  for (auto& [id, bias] : b.biases) v.push_back(&bias);
  v.push_back(b.ex.data());
  return v;
}

Built build(const CalibrationRun& run,
            const CalibrationOptions& options,
            const BatchPoint& at,
            bool robust) {
  if (at.poses.size() != run.frames.size())
    throw InputError("batch: the starting point has " + std::to_string(at.poses.size()) +
                     " poses for " + std::to_string(run.frames.size()) + " frames");
  Built b;
  ceres::Problem::Options po;
  // The association removes thousands of bearings and hundreds of points from problems of
  // 10^5 bearings; without the index each removal scans the whole problem.
  po.enable_fast_removal = true;
  b.problem = std::make_unique<ceres::Problem>(po);
  b.poses.resize(at.poses.size());
  for (std::size_t k = 0; k < at.poses.size(); ++k)
    b.poses[k] = {at.poses[k](0), at.poses[k](1), at.poses[k](2)};
  b.ex = {at.extrinsics.phi, at.extrinsics.rho, at.extrinsics.psi};

  // Track lengths: only tracks long enough (and with a starting point) enter.
  std::map<int, int> length;
  for (const FrameInput& f : run.frames)
    for (const BearingObservation& o : f.observations) ++length[o.track_id];
  for (const auto& [id, n] : length) {
    auto it = at.features.find(id);
    if (n >= options.association.min_track_length && it != at.features.end() &&
        it->second.allFinite())
      b.features[id] = {it->second(0), it->second(1)};
  }

  for (auto& p : b.poses) b.problem->AddParameterBlock(p.data(), 3);
  b.problem->SetParameterBlockConstant(b.poses[0].data());  // gauge: frame 0 is the origin
  b.problem->AddParameterBlock(b.ex.data(), 3);
  // The time offset's correction, with its prior (RefinementOptions::estimate_time_offset).
  const bool timed = options.refinement.estimate_time_offset && run.clock &&
                     run.clock->image_t.size() == run.frames.size() && run.clock->t.size() >= 2 &&
                     options.robot.wheel_base > 0.0;
  if (timed) {
    b.time_offset = {at.time_offset};
    b.problem->AddResidualBlock(
        new ceres::AutoDiffCostFunction<TimeOffsetPrior, 1, 1>(
            new TimeOffsetPrior{1.0 / options.refinement.time_offset_prior_sigma_s}),
        nullptr,
        b.time_offset.data());
  }

  const double K = options.robot.odometry_K * options.refinement.odometry_inflation;
  for (std::size_t k = 1; k < run.frames.size(); ++k) {
    const FrameInput& f = run.frames[k];
    // Covariance of (d_right, d_left, lateral): eq. (31) over the frame's wheel samples
    // (compose_wheel_steps), or over the frame as one step; with the side slip allowed
    // (lateral_sigma) and the floor.
    Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
    if (!f.covariance_per_K.isZero()) {
      S = K * f.covariance_per_K;
      S(0, 0) += options.robot.odometry_variance_floor;
      S(1, 1) += options.robot.odometry_variance_floor;
    } else {
      S.topLeftCorner<2, 2>() =
          chong_kleeman_covariance(f.d_right, f.d_left, K, options.robot.odometry_variance_floor);
    }
    S(2, 2) += options.robot.lateral_sigma * options.robot.lateral_sigma;
    // W = L^-1 with S = L L^T: W^T W = S^-1.
    const Eigen::LLT<Eigen::Matrix3d> llt(S);
    const Eigen::Matrix3d W = llt.matrixL().solve(Eigen::Matrix3d::Identity());
    const OdometryResidual step{f.d_right, f.d_left, f.lateral, options.robot.wheel_base, W};
    if (timed) {
      auto* cost = new ceres::AutoDiffCostFunction<TimedOdometryResidual, 3, 3, 3, 1>(
          new TimedOdometryResidual{
              step, run.clock, run.clock->image_t[k - 1], run.clock->image_t[k]});
      b.odometry_blocks.push_back(b.problem->AddResidualBlock(
          cost, nullptr, b.poses[k - 1].data(), b.poses[k].data(), b.time_offset.data()));
    } else {
      auto* cost =
          new ceres::AutoDiffCostFunction<OdometryResidual, 3, 3, 3>(new OdometryResidual(step));
      b.odometry_blocks.push_back(
          b.problem->AddResidualBlock(cost, nullptr, b.poses[k - 1].data(), b.poses[k].data()));
    }
  }
  if (options.noise.track_bias_sigma > 0.0)
    for (const auto& [id, f] : b.features) {
      double* bias = &(b.biases[id] = 0.0);
      b.bias_priors[id] =
          b.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<BiasPrior, 1, 1>(
                                          new BiasPrior{1.0 / options.noise.track_bias_sigma}),
                                      nullptr,
                                      bias);
    }
  for (std::size_t k = 0; k < run.frames.size(); ++k) {
    for (const BearingObservation& o : run.frames[k].observations) {
      auto it = b.features.find(o.track_id);
      if (it == b.features.end()) continue;
      const double inv_sigma = 1.0 / (options.noise.bearing_sigma * o.sigma_scale);
      ceres::LossFunction* loss =
          robust ? new ceres::HuberLoss(options.refinement.huber_sigmas) : nullptr;
      if (auto bias = b.biases.find(o.track_id); bias != b.biases.end())
        b.bearing_blocks.push_back(b.problem->AddResidualBlock(
            new ceres::AutoDiffCostFunction<BiasedBearingResidual, 1, 3, 2, 3, 1>(
                new BiasedBearingResidual{o.beta, inv_sigma}),
            loss,
            b.poses[k].data(),
            it->second.data(),
            b.ex.data(),
            &bias->second));
      else
        b.bearing_blocks.push_back(b.problem->AddResidualBlock(
            new ceres::AutoDiffCostFunction<BearingResidual, 1, 3, 2, 3>(
                new BearingResidual{o.beta, inv_sigma}),
            loss,
            b.poses[k].data(),
            it->second.data(),
            b.ex.data()));
      b.bearing_keys.emplace_back(o.track_id, static_cast<int>(k));
      ++b.num_bearings;
    }
  }
  return b;
}

// The marginal covariance of (phi, rho, psi) and the variance of the time offset's correction
// from the Fisher information J^T J at the solution (without robust loss), by one sparse LDLT
// factorisation and four solves: where ceres::Covariance gives up on a badly scaled problem, the
// observability analysis's fallback holds the offset fixed, and would leave its share out of the
// extrinsics'.
bool marginal_with_time_offset(Built* b,
                               Eigen::Matrix3d* covariance,
                               double* time_offset_variance) {
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = variable_blocks(*b);
  eo.parameter_blocks.push_back(b->time_offset.data());
  eo.apply_loss_function = false;
  ceres::CRSMatrix crs;
  if (!b->problem->Evaluate(eo, nullptr, nullptr, nullptr, &crs) || crs.num_cols < 4) return false;
  // No ridge (information_with_ridge's 1e-10 of the diagonal moved the extrinsics' covariance
  // by 4e-5 of itself: the pose chain is that badly conditioned); a variable without any
  // residual gets a unit diagonal. Scaled to a unit diagonal, F_s = D^-1/2 F D^-1/2, for the
  // factorisation. Only where that fails (a line's direction without information, which
  // makes F singular and its LDLT's solves not finite) is the ridge added, 1e-10 of F_s's unit
  // diagonal: the direction, free of the extrinsics and the offset, then barely touches them.
  const Eigen::SparseMatrix<double> J = sparse_jacobian(crs);
  Eigen::SparseMatrix<double> F = J.transpose() * J;
  for (int i = 0; i < F.rows(); ++i)
    if (!(F.coeff(i, i) > 0.0)) F.coeffRef(i, i) = 1.0;
  const Eigen::VectorXd d = F.diagonal().cwiseSqrt().cwiseInverse();
  F = d.asDiagonal() * F * d.asDiagonal();
  const int n = crs.num_cols;  // the extrinsics, then the correction: the last four columns
  Eigen::Matrix4d C;
  const auto marginal = [&](const Eigen::SparseMatrix<double>& Fs) {
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(Fs);
    if (ldlt.info() != Eigen::Success) return false;
    for (int k = 0; k < 4; ++k) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
      e(n - 4 + k) = 1.0;
      C.col(k) = ldlt.solve(e).tail<4>();
    }
    C = d.tail<4>().asDiagonal() * C * d.tail<4>().asDiagonal();
    return C.allFinite() && (C.diagonal().array() > 0.0).all();
  };
  if (!marginal(F)) {
    Eigen::SparseMatrix<double> ridge(n, n);
    ridge.setIdentity();
    if (!marginal(F + 1e-10 * ridge)) return false;
  }
  *covariance = 0.5 * (C.topLeftCorner<3, 3>() + C.topLeftCorner<3, 3>().transpose());
  *time_offset_variance = C(3, 3);
  return true;
}

ceres::Solver::Options small_solver_options() {
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  so.max_num_iterations = 50;
  so.function_tolerance = 1e-6;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  return so;
}

BatchPoint point_of(const Built& b) {
  BatchPoint p;
  for (const auto& q : b.poses) p.poses.emplace_back(q[0], q[1], q[2]);
  for (const auto& [id, f] : b.features) p.features[id] = Eigen::Vector2d(f[0], f[1]);
  p.extrinsics = {wrap_angle(b.ex[0]), b.ex[1], wrap_angle(b.ex[2])};
  if (!b.time_offset.empty()) p.time_offset = b.time_offset[0];
  return p;
}

}  // namespace omnivert::calib::internal
