#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "calib/factor_paths.hpp"
#include "calib/lanczos.hpp"
#include "calib/noise_check.hpp"

namespace omnivert::calib::internal {

namespace {

using RowMajorJacobian = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// The whitened residuals and Jacobian of the problem's factors (odometry, bearings, track
// bias priors) and each row's cluster.
struct ClusteredRows {
  std::vector<double> r;
  ceres::CRSMatrix crs;
  std::vector<std::vector<int>> rows_of;  // cluster -> its rows
  int first_track = 0;                    // the clusters before are odometry factors
};

bool evaluate_clusters(Built& b, ClusteredRows* out) {
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = variable_blocks(b);
  eo.residual_blocks = b.odometry_blocks;
  eo.residual_blocks.insert(
      eo.residual_blocks.end(), b.bearing_blocks.begin(), b.bearing_blocks.end());
  // A track's bias prior (CalibrationOptions::noise.track_bias_sigma) is a row of that track's
  // cluster: without it the bias is free and the check's information singular along it.
  for (const auto& [id, block] : b.bias_priors) eo.residual_blocks.push_back(block);
  eo.apply_loss_function = false;
  if (!b.problem->Evaluate(eo, nullptr, &out->r, nullptr, &out->crs)) return false;
  const int m = out->crs.num_rows, n = out->crs.num_cols;
  if (m != static_cast<int>(out->r.size()) || n < 3) return false;
  // Cluster of each residual row: odometry factors (3 rows each) are their own clusters,
  // the bearings of a track one cluster. (Pieces of one line that the joins left apart are
  // not independent clusters; grouped by a chain of Wald tests, they changed the verdicts of
  // 1 in 25 runs from pixels with tracks broken every ~10 frames, and took 2 of the 3 "more
  // noise" verdicts away: they are left apart.)
  std::vector<int> cluster(m);
  int row = 0, next = 0;
  for (std::size_t i = 0; i < b.odometry_blocks.size(); ++i, ++next)
    for (int k = 0; k < 3; ++k) cluster[row++] = next;
  std::map<int, int> of_track;
  auto track_cluster = [&of_track, &next](int id) {
    auto [it, fresh] = of_track.emplace(id, next);
    if (fresh) ++next;
    return it->second;
  };
  for (const auto& key : b.bearing_keys) cluster[row++] = track_cluster(key.track);
  for (const auto& [id, block] : b.bias_priors) cluster[row++] = track_cluster(id);
  if (row != m) return false;
  out->rows_of.assign(next, {});
  for (int i = 0; i < m; ++i) out->rows_of[cluster[i]].push_back(i);
  out->first_track = static_cast<int>(b.odometry_blocks.size());
  return true;
}

// F^-1 as the check needs it: A^T (n x 3, the extrinsics' columns), and for the leverage the
// dense inverse or the sparse factor. Below a few thousand variables the dense inverse is the
// cheaper way (1440 variables: the sparse solves took 60 s, their factor fills in); above,
// sparse solves.
struct InverseInformation {
  bool dense = true;
  Eigen::MatrixXd Finv;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  Eigen::MatrixXd At;  // n x 3: A^T
};

bool invert_information(const Eigen::SparseMatrix<double>& F,
                        int dense_limit,
                        InverseInformation* out) {
  const int n = static_cast<int>(F.rows());
  out->dense = n <= dense_limit;
  if (out->dense) {
    const Eigen::LDLT<Eigen::MatrixXd> dl{Eigen::MatrixXd(F)};
    if (dl.info() != Eigen::Success) return false;
    out->Finv = dl.solve(Eigen::MatrixXd::Identity(n, n));
    if (!out->Finv.allFinite()) return false;
    out->At = out->Finv.rightCols(3);
  } else {
    out->ldlt.compute(F);
    if (out->ldlt.info() != Eigen::Success) return false;
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, 3);
    for (int k = 0; k < 3; ++k) E(n - 3 + k, k) = 1.0;
    out->At = out->ldlt.solve(E);
    if (out->ldlt.info() != Eigen::Success || !out->At.allFinite()) return false;
  }
  return true;
}

// Leverage of a track (its rows): H_cc = J_c F^-1 J_c^T (nc x nc).
Eigen::MatrixXd track_leverage(const InverseInformation& inv,
                               FactorPaths* paths,
                               const RowMajorJacobian& Jr,
                               const std::vector<int>& rows) {
  const int nc = static_cast<int>(rows.size());
  if (inv.dense) {
    // Only the variables the track touches (its feature, its frames' poses, the
    // extrinsics): H_cc = J_cS [F^-1]_SS J_cS^T.
    std::vector<int> cols;
    for (int k = 0; k < nc; ++k)
      for (RowMajorJacobian::InnerIterator it(Jr, rows[k]); it; ++it)
        cols.push_back(static_cast<int>(it.col()));
    std::sort(cols.begin(), cols.end());
    cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
    const int ns = static_cast<int>(cols.size());
    Eigen::MatrixXd Jc = Eigen::MatrixXd::Zero(nc, ns);
    for (int k = 0; k < nc; ++k)
      for (RowMajorJacobian::InnerIterator it(Jr, rows[k]); it; ++it)
        Jc(k,
           std::lower_bound(cols.begin(), cols.end(), static_cast<int>(it.col())) - cols.begin()) =
            it.value();
    Eigen::MatrixXd Fs(ns, ns);
    for (int a = 0; a < ns; ++a)
      for (int c2 = 0; c2 < ns; ++c2) Fs(a, c2) = inv.Finv(cols[a], cols[c2]);
    return Jc * Fs * Jc.transpose();
  }
  // P F P^T = L D L^T, so J_c F^-1 J_c^T = Y^T D^-1 Y with Y = L^-1 P J_c^T: the forward
  // substitution alone, over the rows it reaches (factor_paths.hpp).
  std::vector<std::vector<std::pair<int, double>>> columns(nc);
  for (int k = 0; k < nc; ++k)
    for (RowMajorJacobian::InnerIterator it(Jr, rows[k]); it; ++it)
      columns[k].emplace_back(static_cast<int>(it.col()), it.value());
  const FactorPaths::Forward y = paths->solve(columns);
  return paths->gram(y, y);
}

// A track's share of the extrinsics' error, A J_c^T e_c, with its errors e_c estimated from
// its fitted residuals r_c (nc) as (I - H_cc)^-1/2 r_c; U_c (nc x 3): rows A J_i^T.
// The track's own feature point is determined by the track alone: along its two directions
// I - H_cc is singular (r_c and the columns of U_c have no component there, by the normal
// equations and A F_{:,f} = 0), so the inverse is taken on the complement.
Eigen::Vector3d track_score(const Eigen::MatrixXd& H,
                            const Eigen::VectorXd& rc,
                            const Eigen::MatrixXd& Uc) {
  const int nc = static_cast<int>(rc.size());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eh(Eigen::MatrixXd::Identity(nc, nc) - H);
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(nc);
  for (int k = 0; k < nc; ++k)
    if (eh.eigenvalues()(k) > 1e-6) inv(k) = 1.0 / std::sqrt(eh.eigenvalues()(k));
  const Eigen::VectorXd e =
      eh.eigenvectors() * inv.asDiagonal() * (eh.eigenvectors().transpose() * rc);
  return Uc.transpose() * e;
}

// track_score without H_cc: (I - H_cc)^-1/2 r_c by the Lanczos iteration on products
// (I - H_cc) v = v - J_c F^-1 J_c^T v, each a solve with the whole factor; its cost grows with
// the track's length, not with its cube. Empty when the iteration did not converge.
std::optional<Eigen::Vector3d> long_track_score(const InverseInformation& inv,
                                                const RowMajorJacobian& Jr,
                                                const std::vector<int>& rows,
                                                const Eigen::VectorXd& rc,
                                                const Eigen::MatrixXd& Uc) {
  const int nc = static_cast<int>(rows.size());
  auto apply = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(Jr.cols());
    for (int k = 0; k < nc; ++k)
      for (RowMajorJacobian::InnerIterator it(Jr, rows[k]); it; ++it)
        g(it.col()) += it.value() * v(k);
    const Eigen::VectorXd x =
        inv.dense ? Eigen::VectorXd(inv.Finv * g) : Eigen::VectorXd(inv.ldlt.solve(g));
    Eigen::VectorXd out = v;
    for (int k = 0; k < nc; ++k)
      for (RowMajorJacobian::InnerIterator it(Jr, rows[k]); it; ++it)
        out(k) -= it.value() * x(it.col());
    return out;
  };
  // The floor and the null directions as in track_score.
  const LanczosResult e = lanczos_inverse_sqrt(apply, rc, 1e-6, 1e-10, 400);
  if (!e.converged || !e.x.allFinite()) return std::nullopt;
  return Eigen::Vector3d(Uc.transpose() * e.x);
}

}  // namespace

BatchNoiseCheck noise_check(Built& b, const NoiseCheckOptions& options) {
  BatchNoiseCheck out;
  ClusteredRows rows;
  if (!evaluate_clusters(b, &rows)) return out;
  const Eigen::SparseMatrix<double> J = sparse_jacobian(rows.crs);
  const Eigen::SparseMatrix<double> F = information_with_ridge(J);
  InverseInformation inv;
  if (!invert_information(F, options.dense_limit, &inv)) return out;
  std::optional<FactorPaths> paths;
  if (!inv.dense) paths.emplace(inv.ldlt);
  const Eigen::Matrix3d model = inv.At.bottomRows<3>();
  const Eigen::MatrixXd U = J * inv.At;  // m x 3: row i is A J_i^T
  const int next = static_cast<int>(rows.rows_of.size());
  Eigen::Matrix3d bearing_model = Eigen::Matrix3d::Zero();  // sum over bearing rows u_i u_i^T
  Eigen::Matrix3d clustered = Eigen::Matrix3d::Zero();
  const RowMajorJacobian Jr(J);
  for (int c = rows.first_track; c < next; ++c) {
    const std::vector<int>& of_c = rows.rows_of[c];
    // The fitted residuals are (I - H) e, and the shared variables (poses, extrinsics) take
    // up a good part of a track's errors (on white synthetic bearings the plain sum gives a
    // tenth of the model's covariance), so (I - H_cc)^-1/2 r_c stands in for the track's
    // errors (Bell and McCaffrey's bias-reduced sandwich, "CR2": unbiased when the model is
    // right; the jackknife's (I - H_cc)^-1 gives 2.8 times the model's covariance on white
    // bearings with 10 tracks).
    const int nc = static_cast<int>(of_c.size());
    Eigen::VectorXd rc(nc);
    Eigen::MatrixXd Uc(nc, 3);
    for (int k = 0; k < nc; ++k) {
      rc(k) = rows.r[of_c[k]];
      Uc.row(k) = U.row(of_c[k]);
    }
    bearing_model += Uc.transpose() * Uc;
    std::optional<Eigen::Vector3d> sc;
    if (nc > options.dense_track_limit) sc = long_track_score(inv, Jr, of_c, rc, Uc);
    if (!sc) sc = track_score(track_leverage(inv, paths ? &*paths : nullptr, Jr, of_c), rc, Uc);
    clustered += *sc * sc->transpose();
  }
  const Eigen::LDLT<Eigen::Matrix3d> bi(bearing_model);
  if (bi.info() != Eigen::Success || !(bearing_model.trace() > 0.0)) return out;
  out.model_covariance = model;
  out.bearing_part = bearing_model;
  out.bearing_clustered = clustered;
  out.clusters = next - rows.first_track;
  out.scale = bi.solve(clustered).trace() / 3.0;
  out.covariance = model + (out.scale - 1.0) * bearing_model;
  out.ok = std::isfinite(out.scale) && out.scale > 0.0;
  return out;
}

}  // namespace omnivert::calib::internal
