#include "calib/marginal_information.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace omnivert::calib::internal {

namespace {

// A direction of the scaled nuisance block with information below this fraction of the block's
// largest eigenvalue carries none (a feature seen without parallax): it is left out of the
// Schur complement (pseudo-inverse).
constexpr double kRelativeFloor = 1e-14;

// Steps of iterative refinement of the sparse solve (marginal_information_sparse).
constexpr int kRefinements = 3;

// Jacobi scaling of the nuisance variables (the first n - 3): 1 / sqrt(F_ii), 1 on an empty
// variable; the extrinsics keep their units.
Eigen::VectorXd jacobi_scale(const Eigen::VectorXd& diagonal) {
  const Eigen::Index n = diagonal.size();
  Eigen::VectorXd s = Eigen::VectorXd::Ones(n);
  for (Eigen::Index i = 0; i + 3 < n; ++i)
    if (diagonal(i) > 0.0) s(i) = 1.0 / std::sqrt(diagonal(i));
  return s;
}

// Largest eigenvalue of the scaled nuisance block (the first n - 3 rows and columns of Fs),
// by power iteration from the all-ones vector: it only sets the floor (kRelativeFloor), where
// a few per cent do not matter. O(iterations x nonzeros).
double nuisance_lambda_max(const Eigen::SparseMatrix<double>& Fs) {
  const Eigen::Index n = Fs.rows(), no = n - 3;
  if (no <= 0) return 0.0;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  x.head(no).setOnes();
  x.normalize();
  double lambda = 0.0;
  for (int it = 0; it < 100; ++it) {
    Eigen::VectorXd y = Fs * x;
    y.tail<3>().setZero();
    const double next = x.dot(y), norm = y.norm();
    if (!(norm > 0.0)) return 0.0;
    x = y / norm;
    const bool settled = std::abs(next - lambda) <= 1e-6 * next;
    lambda = next;
    if (settled) break;
  }
  return lambda;
}

// The poses' reduced information, lower triangle, by 3 x 3 blocks (block row >= column).
class BlockLower {
 public:
  explicit BlockLower(int blocks) : blocks_(blocks) {}
  Eigen::Matrix3d& at(int row, int col) {
    auto [it, fresh] = map_.try_emplace(static_cast<std::int64_t>(row) * blocks_ + col);
    if (fresh) it->second.setZero();
    return it->second;
  }
  // As a sparse matrix (lower triangle, what SimplicialLDLT<..., Lower> reads).
  Eigen::SparseMatrix<double> lower() const {
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(map_.size() * 9);
    for (const auto& [key, m] : map_) {
      const int r = static_cast<int>(key / blocks_), c = static_cast<int>(key % blocks_);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          if (r > c || i >= j) t.emplace_back(3 * r + i, 3 * c + j, m(i, j));
    }
    Eigen::SparseMatrix<double> L(3 * blocks_, 3 * blocks_);
    L.setFromTriplets(t.begin(), t.end());
    return L;
  }

 private:
  std::int64_t blocks_;
  std::unordered_map<std::int64_t, Eigen::Matrix3d> map_;
};

// One track's columns of the scaled information: its own block A (k x k, its point and bias),
// its coupling B to the poses it was seen from (3 rows per pose block, in `poses`), and E to
// the extrinsics (3 x k).
struct TrackBlock {
  Eigen::MatrixXd A, B, E;
  std::vector<int> poses;  // pose blocks, ascending
};

TrackBlock track_block(const Eigen::SparseMatrix<double>& Fs,
                       const std::vector<int>& cols,
                       const std::vector<int>& owner,
                       int track,
                       int num_pose_columns,
                       int extrinsics_column) {
  const int k = static_cast<int>(cols.size());
  TrackBlock t;
  t.A = Eigen::MatrixXd::Zero(k, k);
  t.E = Eigen::MatrixXd::Zero(3, k);
  for (int c : cols)
    for (Eigen::SparseMatrix<double>::InnerIterator it(Fs, c); it; ++it)
      if (it.row() < num_pose_columns) t.poses.push_back(static_cast<int>(it.row()) / 3);
  std::sort(t.poses.begin(), t.poses.end());
  t.poses.erase(std::unique(t.poses.begin(), t.poses.end()), t.poses.end());
  t.B = Eigen::MatrixXd::Zero(3 * static_cast<Eigen::Index>(t.poses.size()), k);
  for (int a = 0; a < k; ++a)
    for (Eigen::SparseMatrix<double>::InnerIterator it(Fs, cols[a]); it; ++it) {
      const int r = static_cast<int>(it.row());
      if (r < num_pose_columns) {
        const auto q = std::lower_bound(t.poses.begin(), t.poses.end(), r / 3) - t.poses.begin();
        t.B(3 * q + r % 3, a) = it.value();
      } else if (r >= extrinsics_column) {
        t.E(r - extrinsics_column, a) = it.value();
      } else if (owner[r] == track) {
        t.A(std::find(cols.begin(), cols.end(), r) - cols.begin(), a) = it.value();
      } else {
        // A bearing touches one feature: two tracks never share a row of F.
        throw std::logic_error("marginal information: two tracks coupled");
      }
    }
  return t;
}

// Pseudo-inverse of a track's (scaled) block, directions below `floor` left out; counts them.
Eigen::MatrixXd block_pseudo_inverse(const Eigen::MatrixXd& A, double floor, int* dropped) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A);
  const Eigen::Index k = A.rows();
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    if (es.eigenvalues()(i) > floor)
      inv(i) = 1.0 / es.eigenvalues()(i);
    else
      ++*dropped;
  }
  return es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
}

// Solves Foo Y = R for the scaled nuisance block Foo (poses, then the tracks' columns). A
// track whose own block A (its point and bias) has a direction below `floor` (a line seen
// without parallax) is eliminated on its own, with the pseudo-inverse of A (features are
// independent given the poses and the extrinsics): its Schur complement -B A^+ B^T goes to the
// poses' blocks it couples. The poses and the other tracks are solved together by a sparse
// LDLT in a fill-reducing (AMD) order: where lines are seen from all along the run (the hall),
// eliminating every track first would leave the poses' chain dense.
class NuisanceSolver {
 public:
  NuisanceSolver(const Eigen::SparseMatrix<double>& Fs, const VariableLayout& layout, double floor)
      : np_(layout.num_pose_columns) {
    const int n = static_cast<int>(Fs.rows()), ex = layout.extrinsics_column;
    std::vector<int> owner(static_cast<std::size_t>(n), -1);
    for (std::size_t t = 0; t < layout.track_columns.size(); ++t)
      for (int c : layout.track_columns[t])
        owner[static_cast<std::size_t>(c)] = static_cast<int>(t);
    for (int c = np_; c < ex; ++c)
      if (owner[static_cast<std::size_t>(c)] < 0)
        throw std::logic_error("marginal information: a column of no track");
    BlockLower R(np_ / 3);
    for (int c = 0; c < np_; ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(Fs, c); it; ++it) {
        const int r = static_cast<int>(it.row());
        if (r < np_ && r >= c) R.at(r / 3, c / 3)(r % 3, c % 3) += it.value();
      }
    system_index_.assign(static_cast<std::size_t>(ex), -1);
    for (int c = 0; c < np_; ++c) system_index_[static_cast<std::size_t>(c)] = c;
    int next = np_;
    for (std::size_t t = 0; t < layout.track_columns.size(); ++t) {
      Track tr;
      tr.cols = layout.track_columns[t];
      TrackBlock b = track_block(Fs, tr.cols, owner, static_cast<int>(t), np_, ex);
      int dropped = 0;
      tr.Ainv = block_pseudo_inverse(b.A, floor, &dropped);
      if (dropped == 0) {  // solved with the poses
        for (int c : tr.cols) system_index_[static_cast<std::size_t>(c)] = next++;
        kept_columns_.insert(kept_columns_.end(), tr.cols.begin(), tr.cols.end());
        continue;
      }
      dropped_ += dropped;
      const Eigen::MatrixXd GBt = b.B * tr.Ainv * b.B.transpose();
      const int m = static_cast<int>(b.poses.size());
      for (int i = 0; i < m; ++i)
        for (int j = 0; j <= i; ++j) R.at(b.poses[i], b.poses[j]) -= GBt.block(3 * i, 3 * j, 3, 3);
      tr.B = std::move(b.B);
      tr.poses = std::move(b.poses);
      tracks_.push_back(std::move(tr));
    }
    size_ = next;
    if (size_ > 0) {
      const Eigen::SparseMatrix<double> K = system(Fs, R);
      reduced_nonzeros_ = K.nonZeros();
      ldlt_.compute(K);
      ok_ = ldlt_.info() == Eigen::Success && (ldlt_.vectorD().array() > 0.0).all();
    }
  }

  bool ok() const { return ok_; }
  int dropped() const { return dropped_; }
  long long reduced_nonzeros() const { return reduced_nonzeros_; }

  // Y = Foo^+ R (R: the nuisance rows, any number of columns).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& R) const {
    const Eigen::Index nc = R.cols();
    Eigen::MatrixXd rhs(size_, nc);
    rhs.topRows(np_) = R.topRows(np_);
    for (int c : kept_columns_) rhs.row(system_index_[static_cast<std::size_t>(c)]) = R.row(c);
    std::vector<Eigen::MatrixXd> rt(tracks_.size());
    for (std::size_t t = 0; t < tracks_.size(); ++t) {
      const Track& tr = tracks_[t];
      rt[t].resize(static_cast<Eigen::Index>(tr.cols.size()), nc);
      for (std::size_t a = 0; a < tr.cols.size(); ++a) rt[t].row(a) = R.row(tr.cols[a]);
      const Eigen::MatrixXd g = tr.B * (tr.Ainv * rt[t]);
      for (std::size_t i = 0; i < tr.poses.size(); ++i)
        rhs.middleRows(3 * tr.poses[i], 3) -= g.middleRows(3 * i, 3);
    }
    Eigen::MatrixXd Y = Eigen::MatrixXd::Zero(R.rows(), nc);
    if (size_ > 0) {
      const Eigen::MatrixXd x = ldlt_.solve(rhs);
      Y.topRows(np_) = x.topRows(np_);
      for (int c : kept_columns_) Y.row(c) = x.row(system_index_[static_cast<std::size_t>(c)]);
    }
    for (std::size_t t = 0; t < tracks_.size(); ++t) {
      const Track& tr = tracks_[t];
      Eigen::MatrixXd yp(3 * static_cast<Eigen::Index>(tr.poses.size()), nc);
      for (std::size_t i = 0; i < tr.poses.size(); ++i)
        yp.middleRows(3 * i, 3) = Y.middleRows(3 * tr.poses[i], 3);
      const Eigen::MatrixXd yt = tr.Ainv * (rt[t] - tr.B.transpose() * yp);
      for (std::size_t a = 0; a < tr.cols.size(); ++a) Y.row(tr.cols[a]) = yt.row(a);
    }
    return Y;
  }

 private:
  struct Track {
    std::vector<int> cols, poses;
    Eigen::MatrixXd Ainv, B;
  };

  // The system of the poses and the kept tracks (lower triangle): the poses' blocks (with the
  // Schur complements of the tracks eliminated on their own), the kept tracks' entries of Fs.
  Eigen::SparseMatrix<double> system(const Eigen::SparseMatrix<double>& Fs,
                                     const BlockLower& poses) const {
    const Eigen::SparseMatrix<double> P = poses.lower();
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(static_cast<std::size_t>(P.nonZeros()));
    for (int c = 0; c < P.outerSize(); ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(P, c); it; ++it)
        t.emplace_back(static_cast<int>(it.row()), c, it.value());
    for (int c : kept_columns_) {
      const int sc = system_index_[static_cast<std::size_t>(c)];
      for (Eigen::SparseMatrix<double>::InnerIterator it(Fs, c); it; ++it) {
        const auto r = static_cast<std::size_t>(it.row());
        if (r >= system_index_.size()) continue;  // the extrinsics
        const int sr = system_index_[r];
        if (sr < 0) continue;
        if (sr >= sc) t.emplace_back(sr, sc, it.value());
        if (sr < np_) t.emplace_back(sc, sr, it.value());  // a pose row: its transpose
      }
    }
    Eigen::SparseMatrix<double> K(size_, size_);
    K.setFromTriplets(t.begin(), t.end());
    return K;
  }

  int np_ = 0, size_ = 0;
  std::vector<int> system_index_;  // nuisance column -> row of the system (-1: eliminated)
  std::vector<int> kept_columns_;  // the tracks' columns solved with the poses
  std::vector<Track> tracks_;      // the tracks eliminated on their own
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> ldlt_;
  bool ok_ = true;
  int dropped_ = 0;
  long long reduced_nonzeros_ = 0;
};

}  // namespace

VariableLayout layout_of(const Built& b) {
  VariableLayout l;
  l.num_pose_columns = 3 * static_cast<int>(b.poses.size() > 0 ? b.poses.size() - 1 : 0);
  int col = l.num_pose_columns;
  std::vector<int> ids;
  for (const auto& [id, f] : b.features) {
    ids.push_back(id);
    l.track_columns.push_back({col, col + 1});
    col += 2;
  }
  for (const auto& [id, bias] : b.biases) {
    const auto it = std::lower_bound(ids.begin(), ids.end(), id);
    if (it != ids.end() && *it == id)
      l.track_columns[static_cast<std::size_t>(it - ids.begin())].push_back(col);
    else
      l.track_columns.push_back({col});  // a bias without its feature: a track of its own
    ++col;
  }
  l.extrinsics_column = col;
  return l;
}

Eigen::SparseMatrix<double> fisher_information(Built& b) {
  Eigen::SparseMatrix<double> J;
  if (!whole_jacobian(b, &J)) return {};
  return Eigen::SparseMatrix<double>(J.transpose() * J);
}

Eigen::Matrix3d marginal_information_dense(const Eigen::MatrixXd& F) {
  const int n = static_cast<int>(F.rows()), no = n - 3;
  const Eigen::VectorXd scale = jacobi_scale(F.diagonal()).head(no);
  const Eigen::MatrixXd Foo = scale.asDiagonal() * F.topLeftCorner(no, no) * scale.asDiagonal();
  const Eigen::MatrixXd Foe = scale.asDiagonal() * F.topRightCorner(no, 3);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Foo);
  const Eigen::VectorXd& lam = es.eigenvalues();
  const double lmax = lam.cwiseAbs().maxCoeff();
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(no);
  for (int i = 0; i < no; ++i)
    if (lam(i) > kRelativeFloor * lmax) inv(i) = 1.0 / lam(i);
  const Eigen::MatrixXd UtFoe = es.eigenvectors().transpose() * Foe;
  Eigen::Matrix3d S = F.bottomRightCorner<3, 3>() - UtFoe.transpose() * inv.asDiagonal() * UtFoe;
  S = 0.5 * (S + S.transpose()).eval();
  return S;
}

Eigen::Matrix3d marginal_information_sparse(const Eigen::SparseMatrix<double>& F,
                                            const VariableLayout& layout,
                                            SparseMarginalStats* stats) {
  SparseMarginalStats local;
  SparseMarginalStats& st = stats ? *stats : local;
  const int n = static_cast<int>(F.rows()), ex = layout.extrinsics_column;
  if (ex != n - 3 || layout.num_pose_columns % 3 != 0)
    throw std::logic_error("marginal information: layout");
  const Eigen::VectorXd scale = jacobi_scale(Eigen::VectorXd(F.diagonal()));
  const Eigen::SparseMatrix<double> Fs = scale.asDiagonal() * F * scale.asDiagonal();
  st.nuisance_lambda_max = nuisance_lambda_max(Fs);
  const NuisanceSolver solver(Fs, layout, kRelativeFloor * st.nuisance_lambda_max);
  st.dropped_directions = solver.dropped();
  st.reduced_nonzeros = solver.reduced_nonzeros();
  st.ok = solver.ok();
  if (!st.ok) return Eigen::Matrix3d::Zero();
  // Foe (scaled) and Fee; Y = Foo^+ Foe with iterative refinement on the residual of the whole
  // (sparse) system: it restores the digits an ill-conditioned factorisation loses (the turn in
  // place of marginal_information_test: 1e-5 relative on the bounds without, 2e-7 with).
  Eigen::MatrixXd Foe = Eigen::MatrixXd::Zero(ex, 3);
  Eigen::Matrix3d Fee = Eigen::Matrix3d::Zero();
  for (int k = 0; k < 3; ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(Fs, ex + k); it; ++it)
      (it.row() < ex ? Foe(it.row(), k) : Fee(it.row() - ex, k)) = it.value();
  Eigen::MatrixXd Y = solver.solve(Foe);
  Eigen::Matrix3d S = Fee - Foe.transpose() * Y;
  for (int it = 0; it < kRefinements; ++it) {
    Eigen::MatrixXd padded = Eigen::MatrixXd::Zero(n, 3);
    padded.topRows(ex) = Y;
    const Eigen::MatrixXd residual = Foe - (Fs * padded).topRows(ex);
    Y += solver.solve(residual);
    const Eigen::Matrix3d next = Fee - Foe.transpose() * Y;
    const double change = (next - S).norm();
    S = next;
    if (change <= 1e-15 * S.norm()) break;
  }
  st.ok = S.allFinite();
  S = 0.5 * (S + S.transpose()).eval();
  return S;
}

}  // namespace omnivert::calib::internal
