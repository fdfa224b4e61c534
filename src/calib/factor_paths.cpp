#include "calib/factor_paths.hpp"

#include <algorithm>
#include <cstddef>

namespace omnivert::calib::internal {

FactorPaths::FactorPaths(const Factor& factor) : factor_(factor) {
  // L's strictly lower part, column by column, its rows ascending (Eigen's up-looking
  // factorisation fills each column in increasing row order); the unit diagonal is implied.
  const auto& L = factor_.matrixL().nestedExpression();
  const int n = static_cast<int>(L.cols());
  parent_.assign(n, -1);
  where_.assign(n, -1);
  const auto* outer = L.outerIndexPtr();
  const auto* inner = L.innerIndexPtr();
  for (int j = 0; j < n; ++j)
    if (outer[j] < outer[j + 1]) parent_[j] = inner[outer[j]];
}

FactorPaths::Forward FactorPaths::solve(
    const std::vector<std::vector<std::pair<int, double>>>& columns) {
  const auto& P = factor_.permutationP();
  Forward out;
  // The rows reached: every path from a row P b touches up to the root.
  for (const auto& column : columns)
    for (const auto& [variable, value] : column)
      for (int r = P.indices()(variable); r != -1 && where_[r] == -1; r = parent_[r]) {
        where_[r] = 0;
        out.rows.push_back(r);
      }
  std::sort(out.rows.begin(), out.rows.end());
  const int m = static_cast<int>(out.rows.size());
  for (int i = 0; i < m; ++i) where_[out.rows[i]] = i;
  out.Y.setZero(m, static_cast<Eigen::Index>(columns.size()));
  for (std::size_t k = 0; k < columns.size(); ++k)
    for (const auto& [variable, value] : columns[k])
      out.Y(where_[P.indices()(variable)], static_cast<Eigen::Index>(k)) += value;
  // L y = P b over the reached rows, in ascending order: column j of L only reaches rows on
  // j's path, which are all in the set.
  const auto& L = factor_.matrixL().nestedExpression();
  const auto* outer = L.outerIndexPtr();
  const auto* inner = L.innerIndexPtr();
  const double* value = L.valuePtr();
  // On raw rows (Y is row-major): the same products and differences, in the same order, as
  // the row expressions they replace, without an expression's setup for rows of 2-6 entries.
  const int nc = static_cast<int>(columns.size());
  double* Y = out.Y.data();
  for (int i = 0; i < m; ++i) {
    const double* yi = Y + static_cast<std::ptrdiff_t>(i) * nc;
    if (std::all_of(yi, yi + nc, [](double v) { return v == 0.0; })) continue;
    const int j = out.rows[i];
    for (auto p = outer[j]; p < outer[j + 1]; ++p) {
      double* yr = Y + static_cast<std::ptrdiff_t>(where_[inner[p]]) * nc;
      const double v = value[p];
      for (int c = 0; c < nc; ++c) yr[c] -= v * yi[c];
    }
  }
  for (const int r : out.rows) where_[r] = -1;
  return out;
}

Eigen::MatrixXd FactorPaths::gram(const Forward& a, const Forward& c) const {
  const auto& D = factor_.vectorD();
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(a.Y.cols(), c.Y.cols());
  if (&a == &c) {
    Eigen::VectorXd w(a.rows.size());
    for (std::size_t i = 0; i < a.rows.size(); ++i) w(i) = 1.0 / D(a.rows[i]);
    G.noalias() = a.Y.transpose() * w.asDiagonal() * a.Y;
    return G;
  }
  for (std::size_t i = 0, j = 0; i < a.rows.size() && j < c.rows.size();) {
    if (a.rows[i] < c.rows[j]) {
      ++i;
    } else if (c.rows[j] < a.rows[i]) {
      ++j;
    } else {
      G.noalias() += a.Y.row(i).transpose() * c.Y.row(j) / D(a.rows[i]);
      ++i;
      ++j;
    }
  }
  return G;
}

}  // namespace omnivert::calib::internal
