#pragma once
// Blocks of F^-1 from the sparse factor P F P^T = L D L^T, touching only what they need.
//
// For a few columns B of the identity or of J^T (entries b), B^T F^-1 C = Y_B^T D^-1 Y_C with
// Y = L^-1 P B: the forward substitution alone. The non-zero rows of L^-1 P b are the
// elimination-tree paths from the rows P b touches up to the root (Gilbert and Peierls; the
// parent of column j is the first row below the diagonal in L's column j), so each solve runs
// over those rows only, never over the whole factor nor a dense column of the run's length.
// On a long run whose factor's elimination tree is bushy (a fill-reducing order), the paths are
// short: the cost of a track's leverage no longer grows with the run.
//
// Not thread-safe: the object keeps a work array of the factor's size.

#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace omnivert::calib::internal {

class FactorPaths {
 public:
  using Factor = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>;

  // Y = L^-1 P B restricted to its non-zero rows `rows` (ascending, in the factor's order).
  struct Forward {
    std::vector<int> rows;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>
        Y;  // rows x columns of B
  };

  // `factor` must outlive this object and be computed (info() == Success).
  explicit FactorPaths(const Factor& factor);

  // B's column k has the entries columns[k]: (variable index in F's order, value).
  Forward solve(const std::vector<std::vector<std::pair<int, double>>>& columns);

  // Y_a^T D^-1 Y_c over the rows both have (the others contribute zero).
  Eigen::MatrixXd gram(const Forward& a, const Forward& c) const;

 private:
  const Factor& factor_;
  std::vector<int> parent_;  // elimination tree; -1 at a root
  std::vector<int> where_;   // work: factor row -> index in the current Forward, or -1
};

}  // namespace omnivert::calib::internal
