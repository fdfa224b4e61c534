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

#include "calib/batch_problem.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::calib {

using namespace internal;

namespace {

// The Fisher information F = J^T J of the batch problem at its point (n x n, the variables of
// variable_blocks; the residuals are already divided by their sigmas). Frame 0 is not a
// variable (gauge).
Eigen::MatrixXd fisher_information(Built& b) {
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = variable_blocks(b);
  eo.apply_loss_function = false;
  ceres::CRSMatrix crs;
  b.problem->Evaluate(eo, nullptr, nullptr, nullptr, &crs);
  return information_from_jacobian(crs);
}

// Marginal information of the extrinsics: Schur complement of the nuisance block
// (pseudo-inverse, so that features without parallax do not poison it). The nuisance
// variables are scaled to unit information first (Jacobi): poses, features in metres and
// bearings whitened by a small sigma span many orders of magnitude, and unscaled, the
// pseudo-inverse's cut (relative to the largest eigenvalue) dropped the depth of a feature
// seen with little parallax while its coupling to the extrinsics stayed: the bound of
// phi + psi came out 2.2 times too small against the full inverse's
// (Observability.BoundIsTheMarginalOfTheFullInverseOfTheSolvedProblem).
Eigen::Matrix3d marginal_information(const Eigen::MatrixXd& F) {
  const int n = static_cast<int>(F.rows()), no = n - 3;
  Eigen::VectorXd scale(no);
  for (int i = 0; i < no; ++i) scale(i) = F(i, i) > 0.0 ? 1.0 / std::sqrt(F(i, i)) : 1.0;
  const Eigen::MatrixXd Foo = scale.asDiagonal() * F.topLeftCorner(no, no) * scale.asDiagonal();
  const Eigen::MatrixXd Foe = scale.asDiagonal() * F.topRightCorner(no, 3);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Foo);
  const Eigen::VectorXd& lam = es.eigenvalues();
  const double lmax = lam.cwiseAbs().maxCoeff();
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(no);
  for (int i = 0; i < no; ++i)
    if (lam(i) > 1e-14 * lmax) inv(i) = 1.0 / lam(i);
  const Eigen::MatrixXd UtFoe = es.eigenvectors().transpose() * Foe;
  Eigen::Matrix3d S = F.bottomRightCorner<3, 3>() - UtFoe.transpose() * inv.asDiagonal() * UtFoe;
  S = 0.5 * (S + S.transpose()).eval();
  return S;
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
  const Eigen::Matrix3d S = marginal_information(fisher_information(b));
  ObservabilityReport rep;
  judge_information(S, at.extrinsics, options.observability, &rep);
  check_rotation(run, options, at, &rep);
  rep.message = observability_message(rep, options.observability);
  return rep;
}

}  // namespace omnivert::calib
