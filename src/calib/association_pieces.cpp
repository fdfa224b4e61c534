#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <set>
#include <tuple>

#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>

#include "calib/association.hpp"

namespace omnivert::calib::internal {

double one_point_statistic(Built* b, const std::vector<std::size_t>& blocks, int a, int c) {
  auto cost = [&](double* jtj, double* jtr) {
    double s = 0.0;
    for (std::size_t i : blocks) {
      double r = 0.0, j[2] = {0.0, 0.0};
      double* jac[4] = {nullptr, j, nullptr, nullptr};  // (pose, feature, extrinsics[, track bias])
      if (!b->problem->EvaluateResidualBlock(
              b->bearing_blocks[i], false, nullptr, &r, jtj ? jac : nullptr))
        return std::numeric_limits<double>::infinity();
      s += r * r;
      if (jtj) {
        jtj[0] += j[0] * j[0], jtj[1] += j[0] * j[1], jtj[2] += j[1] * j[1];
        jtr[0] += j[0] * r, jtr[1] += j[1] * r;
      }
    }
    return s;
  };
  std::array<double, 2>& fa = b->features.at(a);
  std::array<double, 2>& fc = b->features.at(c);
  const std::array<double, 2> own_a = fa, own_c = fc;
  const double separate = cost(nullptr, nullptr);
  double best = std::numeric_limits<double>::infinity();
  for (const std::array<double, 2>& start : {own_a, own_c}) {
    fa = fc = start;
    for (int it = 0; it < 10; ++it) {
      double h[3] = {0, 0, 0}, g[2] = {0, 0};
      const double now = cost(h, g);
      if (!std::isfinite(now)) break;
      best = std::min(best, now);
      const double det = h[0] * h[2] - h[1] * h[1];
      if (!(det > 0.0)) break;
      const double dx = -(h[2] * g[0] - h[1] * g[1]) / det;
      const double dy = -(h[0] * g[1] - h[1] * g[0]) / det;
      fa[0] += dx, fa[1] += dy;
      fc = fa;
      if (std::hypot(dx, dy) < 1e-9) break;
    }
    best = std::min(best, cost(nullptr, nullptr));
  }
  fa = own_a;
  fc = own_c;
  return best - separate;
}

std::vector<TrackJoin> find_merges(Built* b, int max_gap, double chi2) {
  const std::map<int, std::vector<int>> frames_of = track_frames(*b);
  std::map<int, std::vector<std::size_t>> blocks;  // track id -> its bearings' blocks
  for (std::size_t i = 0; i < b->bearing_keys.size(); ++i)
    blocks[b->bearing_keys[i].track].push_back(i);
  FeatureCovariance covariance;
  std::vector<std::tuple<double, int, int>> passing;  // (statistic, a, c)
  for (auto ia = frames_of.begin(); ia != frames_of.end(); ++ia)
    for (auto ic = std::next(ia); ic != frames_of.end(); ++ic) {
      const std::vector<int>& fa = ia->second;
      const std::vector<int>& fc = ic->second;
      const int gap = std::max(fc.front() - fa.back(), fa.front() - fc.back());
      if (gap > max_gap || share_a_frame(fa, fc)) continue;
      // a: the piece seen first.
      const int a = fa.front() <= fc.front() ? ia->first : ic->first;
      const int c = a == ia->first ? ic->first : ia->first;
      // The Wald test first: after one factorisation per call it costs two small solves per
      // track, where the likelihood ratio re-fits a point to both tracks' bearings.
      if (!(one_line_statistic(b, a, c, &covariance) < chi2)) continue;
      std::vector<std::size_t> both = blocks.at(a);
      both.insert(both.end(), blocks.at(c).begin(), blocks.at(c).end());
      const double lr = one_point_statistic(b, both, a, c);
      if (lr < chi2) passing.emplace_back(lr, a, c);
    }
  std::sort(passing.begin(), passing.end());
  std::set<int> has_successor, has_predecessor;
  std::vector<TrackJoin> out;
  for (const auto& [t, a, c] : passing) {
    if (has_successor.count(a) || has_predecessor.count(c)) continue;
    has_successor.insert(a);
    has_predecessor.insert(c);
    out.emplace_back(a, c);
  }
  return out;
}

std::vector<std::pair<int, int>> find_splits(const Built& b, const AssociationOptions& split) {
  struct Row {
    int frame;
    double r;
    Eigen::Vector2d J;
  };
  std::map<int, std::vector<Row>> seq;
  // Only the feature's Jacobian: Ceres refuses (and logs) a Jacobian of a constant block, and
  // frame 0's pose is constant (the gauge).
  double jf[2];
  double* jac[4] = {nullptr, jf, nullptr, nullptr};  // (pose, feature, extrinsics[, track bias])
  for (std::size_t i = 0; i < b.bearing_blocks.size(); ++i) {  // bearing_keys is parallel
    double r = 0.0, cost = 0.0;
    if (!b.problem->EvaluateResidualBlock(
            b.bearing_blocks[i], /*apply_loss_function=*/false, &cost, &r, jac) ||
        !std::isfinite(r) || !std::isfinite(jf[0]) || !std::isfinite(jf[1]))
      continue;
    seq[b.bearing_keys[i].track].push_back(
        {b.bearing_keys[i].frame, r, Eigen::Vector2d(jf[0], jf[1])});
  }
  struct Candidate {
    double statistic;         // of the track's best split
    int id;                   // the track
    int first, last;          // its span (frames)
    std::vector<int> frames;  // first frames of the new parts, the best split's among them
  };
  std::vector<Candidate> candidates;
  const int m = std::max(split.split_min_bearings, 2);
  auto gain = [](const Eigen::Matrix2d& H, const Eigen::Vector2d& g) {
    const Eigen::Matrix2d Hr = H + 1e-9 * (H.trace() + 1e-12) * Eigen::Matrix2d::Identity();
    return g.dot(Hr.ldlt().solve(g));
  };
  for (auto& [id, v] : seq) {
    const int n = static_cast<int>(v.size());
    if (n < 2 * m) continue;
    std::sort(v.begin(), v.end(), [](const Row& x, const Row& y) { return x.frame < y.frame; });
    std::vector<Eigen::Matrix2d> H(n + 1, Eigen::Matrix2d::Zero());
    std::vector<Eigen::Vector2d> g(n + 1, Eigen::Vector2d::Zero());
    for (int i = 0; i < n; ++i) {
      H[i + 1] = H[i] + v[i].J * v[i].J.transpose();
      g[i + 1] = g[i] + v[i].J * v[i].r;
    }
    // The statistic of splitting the bearings [a, c) at j, and the best j (-1: none).
    auto segment = [&](int a, int c) { return gain(H[c] - H[a], g[c] - g[a]); };
    auto best_split = [&](int a, int c) {
      const double whole = segment(a, c);  // ~0 for the whole track at a solution
      std::pair<double, int> best{0.0, -1};
      for (int j = a + m; j <= c - m; ++j) {
        const double t = segment(a, j) + segment(j, c) - whole;
        if (t > best.first) best = {t, j};
      }
      return best;
    };
    const auto [statistic, j] = best_split(0, n);
    if (j < 0 || !(statistic > split.split_chi2)) continue;
    Candidate c{statistic, id, v.front().frame, v.back().frame, {v[j].frame}};
    // A track that slipped more than once: each part split again where its own statistic,
    // from the same linearisation, passes (binary segmentation).
    std::vector<std::pair<int, int>> parts = {{0, j}, {j, n}};
    while (!parts.empty()) {
      const auto [a, e] = parts.back();
      parts.pop_back();
      const auto [t, k] = best_split(a, e);
      if (k < 0 || !(t > split.split_chi2)) continue;
      c.frames.push_back(v[k].frame);
      parts.push_back({a, k});
      parts.push_back({k, e});
    }
    candidates.push_back(std::move(c));
  }
  // A slip biases the solution near it, and a biased solution leaves structure in the residuals
  // of clean tracks there too: a track is split in this round only if its statistic is within
  // a factor split_keep_fraction of the strongest among the candidates whose spans overlap its
  // own; the others are judged again after the re-solve. (Far from a slip the solution is not
  // moved by it: in a long run most candidates are split in the first round.)
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return std::tie(x.statistic, x.id) > std::tie(y.statistic, y.id);
  });
  std::vector<std::pair<int, int>> out;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const Candidate& c = candidates[i];
    double strongest = c.statistic;
    for (std::size_t k = 0; k < i; ++k)
      if (candidates[k].first <= c.last && c.first <= candidates[k].last)
        strongest = std::max(strongest, candidates[k].statistic);
    if (c.statistic < split.split_keep_fraction * strongest) continue;
    for (int frame : c.frames) out.emplace_back(c.id, frame);
  }
  std::sort(out.begin(), out.end());
  spdlog::debug("association: {} tracks to split, {} splits now", candidates.size(), out.size());
  return out;
}

}  // namespace omnivert::calib::internal
