#include "omnivert/calib/observability.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "calib/batch_problem.hpp"
#include "calib/marginal_information.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::calib {

using namespace internal;

namespace {

// Variables up to which the dense reference is a fallback (seconds at this size).
constexpr Eigen::Index kDenseFallbackLimit = 3000;

// The marginal information of the extrinsics at the problem's point (Sec. 8.1): the Schur
// complement of the poses, features and track biases, computed on the sparse structure
// (marginal_information.hpp; docs/calibration.md#cramer-rao-bounds). Should the sparse system
// not factor, a problem small enough for the dense reference takes it; a larger one is
// reported as determining nothing.
Eigen::Matrix3d marginal_information(Built& b, bool dense_reference) {
  const Eigen::SparseMatrix<double> F = fisher_information(b);
  if (dense_reference) return marginal_information_dense(Eigen::MatrixXd(F));
  SparseMarginalStats stats;
  const Eigen::Matrix3d S = marginal_information_sparse(F, layout_of(b), &stats);
  spdlog::debug(
      "observability: {} variables, {} track directions without information, sparse system "
      "{} nonzeros",
      F.rows(),
      stats.dropped_directions,
      stats.reduced_nonzeros);
  if (stats.ok) return S;
  if (F.rows() <= kDenseFallbackLimit) return marginal_information_dense(Eigen::MatrixXd(F));
  spdlog::warn(
      "observability: the information did not factor; nothing is reported "
      "determined");
  return Eigen::Matrix3d::Zero();
}

// The verdicts on S, the marginal information: its eigenvalues scaled by the thresholds, its
// rank and condition, each parameter's bound, and the inverse.
void judge_information(const Eigen::Matrix3d& S,
                       const Extrinsics& ex,
                       const ObservabilityOptions& obs,
                       ObservabilityReport* out) {
  ObservabilityReport& rep = *out;
  rep.information = S;
  // Scale by the thresholds so that "determined" is "[S~^-1]_ii < 1".
  const Eigen::Vector3d thr(obs.max_sigma_angle, obs.max_sigma_rho, obs.max_sigma_angle);
  const Eigen::Matrix3d St = thr.asDiagonal() * S * thr.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> e3(St);
  rep.eigenvalues = e3.eigenvalues();
  const double emax = std::max(rep.eigenvalues.maxCoeff(), 0.0);
  const double floor = obs.relative_eigenvalue_floor * std::max(emax, 1e-300);
  rep.rank = 0;
  for (int i = 0; i < 3; ++i) rep.rank += rep.eigenvalues(i) > floor ? 1 : 0;
  rep.condition = rep.eigenvalues(0) > floor ? emax / rep.eigenvalues(0)
                                             : std::numeric_limits<double>::infinity();
  const double inf = std::numeric_limits<double>::infinity();
  // Variance of v^T (phi, rho, psi) (v in unscaled units) = sum (v~ . u_k)^2 / lambda_k,
  // infinite when v has a component along a (numerically) null eigenvector.
  auto sigma_of = [&](const Eigen::Vector3d& v) {
    const Eigen::Vector3d vt = v.cwiseProduct(thr);  // S^-1 = T S~^-1 T
    double var = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double c = vt.dot(e3.eigenvectors().col(k));
      if (rep.eigenvalues(k) <= floor) {
        if (std::abs(c) > 1e-6 * vt.norm()) return inf;
        continue;
      }
      var += c * c / rep.eigenvalues(k);
    }
    return std::sqrt(var);
  };
  auto verdict = [&](const Eigen::Vector3d& v, double threshold) {
    ParameterVerdict p;
    p.crlb = sigma_of(v);
    p.determined = p.crlb < threshold;
    return p;
  };
  rep.phi = verdict({1, 0, 0}, obs.max_sigma_angle);
  rep.rho = verdict({0, 1, 0}, obs.max_sigma_rho);
  rep.psi = verdict({0, 0, 1}, obs.max_sigma_angle);
  rep.yaw = verdict({1, 0, 1}, obs.max_sigma_angle);
  rep.x = verdict({-ex.rho * std::sin(ex.phi), std::cos(ex.phi), 0}, obs.max_sigma_rho);
  rep.y = verdict({ex.rho * std::cos(ex.phi), std::sin(ex.phi), 0}, obs.max_sigma_rho);
  if (rep.rank == 3) {
    rep.crlb_covariance = S.ldlt().solve(Eigen::Matrix3d::Identity());
  } else {
    rep.crlb_covariance.setConstant(inf);
  }
}

// Did the robot turn (Sec. 8.1)? Its heading's span against the heading noise of eq. (31)
// accumulated over the run: below min_rotation_sigmas, the information about phi, rho and psi
// individually comes from the estimated trajectory's noise, not from a turn.
void check_rotation(const CalibrationRun& run,
                    const CalibrationOptions& options,
                    const BatchPoint& at,
                    ObservabilityReport* out) {
  const ObservabilityOptions& obs = options.observability;
  ObservabilityReport& rep = *out;
  double lo = 0.0, hi = 0.0, var = 0.0;
  for (std::size_t k = 0; k < at.poses.size(); ++k) {
    lo = std::min(lo, at.poses[k](2) - at.poses[0](2));
    hi = std::max(hi, at.poses[k](2) - at.poses[0](2));
  }
  const double K = options.robot.odometry_K * options.refinement.odometry_inflation;
  for (const FrameInput& f : run.frames) var += K * (std::abs(f.d_right) + std::abs(f.d_left));
  rep.heading_range = hi - lo;
  rep.heading_noise = std::sqrt(var) / options.robot.wheel_base;
  if (rep.heading_range < obs.min_rotation_sigmas * rep.heading_noise)
    for (ParameterVerdict* p : {&rep.phi, &rep.rho, &rep.psi, &rep.x, &rep.y})
      p->determined = false;
}

// What is (not) determined and the motion that would fix it.
std::string observability_message(const ObservabilityReport& rep, const ObservabilityOptions& obs) {
  std::ostringstream m;
  if (rep.all_determined()) {
    m << "phi, rho and psi are determined by this trajectory (Cramer-Rao bounds: phi "
      << rad2deg(rep.phi.crlb) << " deg, rho " << 1e3 * rep.rho.crlb << " mm, psi "
      << rad2deg(rep.psi.crlb) << " deg).";
  } else {
    std::vector<std::string> bad;
    if (!rep.phi.determined) bad.push_back("phi");
    if (!rep.rho.determined) bad.push_back("rho");
    if (!rep.psi.determined) bad.push_back("psi");
    for (std::size_t i = 0; i < bad.size(); ++i)
      m << (i == 0 ? "" : (i + 1 == bad.size() ? " and " : ", ")) << bad[i];
    m << (bad.size() == 1 ? " is" : " are") << " not determined by this trajectory";
    if (rep.yaw.determined)
      m << " (the camera yaw phi + psi is, to " << rad2deg(rep.yaw.crlb)
        << " deg): the camera's position on the robot shows only while the robot turns, and "
           "this run did not turn enough";
    if (rep.yaw.determined && rep.heading_range < obs.min_rotation_sigmas * rep.heading_noise)
      m << " (its heading spans " << rad2deg(rep.heading_range)
        << " deg, within the wheels' noise of " << rad2deg(rep.heading_noise) << " deg)";
    if (rep.yaw.determined)
      m << ". Add a turn in place near features (1-3 m away), or alternate straights and turns "
           "(Sec. 8.1).";
    else
      m << ", not even the camera yaw phi + psi: drive a straight line with vertical lines "
           "around (a few meters away), then turn in place near them (Sec. 8.1).";
  }
  return m.str();
}

}  // namespace

ObservabilityReport analyse_observability(const CalibrationRun& run,
                                          const CalibrationOptions& options,
                                          const BatchPoint& at) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("calibration options: " + why);
  Built b = build(run, options, at, /*robust=*/false);
  const Eigen::Matrix3d S = marginal_information(b, options.observability.dense_reference);
  ObservabilityReport rep;
  judge_information(S, at.extrinsics, options.observability, &rep);
  check_rotation(run, options, at, &rep);
  rep.message = observability_message(rep, options.observability);
  return rep;
}

}  // namespace omnivert::calib
