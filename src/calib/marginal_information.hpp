#pragma once
// The marginal Fisher information of the extrinsics (phi, rho, psi) in the batch problem of
// batch_point.hpp (Sec. 8.1): the Schur complement of the poses, features and track biases
// in F = J^T J. Two ways to the same 3 x 3 matrix:
//   - marginal_information_dense: the plain reference, the whole nuisance block eigen-
//     decomposed (cubic in the run's length, quadratic in memory; tests and small problems);
//   - marginal_information_sparse: a sparse LDLT of the nuisance block in a fill-reducing
//     order, a track without parallax along some direction eliminated on its own first
//     (pseudo-inverse of its block), and iterative refinement; never a dense matrix of the run.
// Both scale the nuisance variables to unit information (Jacobi) and leave out, in that scale,
// the directions with information below 1e-14 of the nuisance block's largest eigenvalue (the
// dense one of the whole block, the sparse one of each track's own block: a feature without
// parallax), docs/calibration.md#cramer-rao-bounds.

#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "calib/batch_problem.hpp"

namespace omnivert::calib::internal {

// Where each variable of F sits (variable_blocks order: poses of frames 1..N, features,
// track biases, extrinsics last).
struct VariableLayout {
  int num_pose_columns = 0;                     // 3 (N - 1), the first columns
  std::vector<std::vector<int>> track_columns;  // each track's: its point's two, its bias'
  int extrinsics_column = 0;                    // the first of the last three
};

VariableLayout layout_of(const Built& b);

// F = J^T J of the batch problem at its point (unwhitened loss: the Gaussian model), sparse;
// empty when Ceres cannot evaluate the problem.
Eigen::SparseMatrix<double> fisher_information(Built& b);

// The plain reference: pseudo-inverse of the whole (scaled) nuisance block by its
// eigen-decomposition.
Eigen::Matrix3d marginal_information_dense(const Eigen::MatrixXd& F);

// What the sparse elimination did, for tests and the log.
struct SparseMarginalStats {
  double nuisance_lambda_max = 0.0;  // largest eigenvalue of the scaled nuisance block
  int dropped_directions = 0;        // of track blocks, below the floor
  long long reduced_nonzeros = 0;    // of the system factored (lower triangle)
  bool ok = false;                   // false: its LDLT failed
};

// The same quantity on the sparse structure; `stats` optional.
Eigen::Matrix3d marginal_information_sparse(const Eigen::SparseMatrix<double>& F,
                                            const VariableLayout& layout,
                                            SparseMarginalStats* stats = nullptr);

}  // namespace omnivert::calib::internal
