#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>

#include <Eigen/Cholesky>

#include "calib/association.hpp"
#include "omnivert/calib/model.hpp"

namespace omnivert::calib::internal {

std::map<int, std::vector<int>> track_frames(const Built& b) {
  std::map<int, std::vector<int>> out;
  for (const auto& [id, k] : b.bearing_keys) out[id].push_back(k);
  for (auto& [id, v] : out) std::sort(v.begin(), v.end());
  return out;
}

bool share_a_frame(const std::vector<int>& a, const std::vector<int>& c) {
  for (std::size_t i = 0, j = 0; i < a.size() && j < c.size();) {
    if (a[i] == c[j]) return true;
    a[i] < c[j] ? ++i : ++j;
  }
  return false;
}

double one_line_statistic(Built* b, int a, int c, FeatureCovariance* cache) {
  constexpr double kNone = std::numeric_limits<double>::infinity();
  if (!cache->ready) {
    cache->ready = true;
    Eigen::SparseMatrix<double> F;
    {
      // J is gone before the factorisation (on a long run it is tens of MB, and the filter's
      // noise check may be doing the same beside).
      Eigen::SparseMatrix<double> J;
      if (!whole_jacobian(*b, &J)) return kNone;
      F = information_with_ridge(J);
    }
    cache->ldlt.compute(F);
    cache->ok = cache->ldlt.info() == Eigen::Success && (cache->ldlt.vectorD().array() > 0).all();
    int col = 3 * (static_cast<int>(b->poses.size()) - 1);
    for (const auto& [id, f] : b->features) {
      cache->column[id] = col;
      col += 2;
    }
  }
  if (!cache->ok) return kNone;
  if (!cache->paths) cache->paths = std::make_unique<FactorPaths>(cache->ldlt);
  // The forward substitution alone (FeatureCovariance::solved), each feature's once.
  auto forward = [cache](int id) -> const FactorPaths::Forward& {
    auto it = cache->solved.find(id);
    if (it != cache->solved.end()) return it->second;
    const int col = cache->column.at(id);
    return cache->solved[id] = cache->paths->solve({{{col, 1.0}}, {{col + 1, 1.0}}});
  };
  const FactorPaths::Forward& Ya = forward(a);
  const FactorPaths::Forward& Yc = forward(c);
  // Cov(f_a - f_c) = Ya^T D^-1 Ya + Yc^T D^-1 Yc - (Ya^T D^-1 Yc + its transpose).
  const Eigen::Matrix2d ac = cache->paths->gram(Ya, Yc);
  const Eigen::Matrix2d C =
      cache->paths->gram(Ya, Ya) + cache->paths->gram(Yc, Yc) - ac - ac.transpose();
  const std::array<double, 2>& fa = b->features.at(a);
  const std::array<double, 2>& fc = b->features.at(c);
  const Eigen::Vector2d d(fa[0] - fc[0], fa[1] - fc[1]);
  const Eigen::LDLT<Eigen::Matrix2d> cl(0.5 * (C + C.transpose()));
  if (cl.info() != Eigen::Success || !(cl.vectorD().array() > 0).all()) return kNone;
  const double t = d.dot(cl.solve(d));
  return std::isfinite(t) ? t : kNone;
}

bool one_line(Built* b, int a, int c, double chi2, FeatureCovariance* cache) {
  return one_line_statistic(b, a, c, cache) < chi2;
}

int reject_crossings(Built* b,
                     double guard,
                     int margin,
                     int min_bearings,
                     const std::map<int, int>& origin,
                     double merge_chi2) {
  if (!(guard > 0.0) || b->features.empty()) return 0;
  std::map<int, std::pair<int, int>> span;  // track id -> (first, last) frame
  for (const auto& [id, k] : b->bearing_keys) {
    auto [it, fresh] = span.emplace(id, std::make_pair(k, k));
    it->second.first = std::min(it->second.first, k);
    it->second.second = std::max(it->second.second, k);
  }
  // Per frame, the direction of each live feature from the camera centre (eq. 16-17).
  const int frames = static_cast<int>(b->poses.size());
  std::vector<std::vector<std::pair<double, int>>> seen(static_cast<std::size_t>(frames));
  for (const auto& [id, f] : b->features) {
    const auto it = span.find(id);
    if (it == span.end()) continue;
    const int from = std::max(it->second.first - margin, 0);
    const int to = std::min(it->second.second + margin, frames - 1);
    for (int k = from; k <= to; ++k) {
      const auto& p = b->poses[static_cast<std::size_t>(k)];
      const double xc = p[0] + b->ex[1] * std::cos(p[2] + b->ex[0]);
      const double yc = p[1] + b->ex[1] * std::sin(p[2] + b->ex[0]);
      seen[static_cast<std::size_t>(k)].emplace_back(std::atan2(f[1] - yc, f[0] - xc), id);
    }
  }
  // Two parts of one split track are one line, not a crossing.
  auto tracker = [&origin](int id) {
    const auto it = origin.find(id);
    return it != origin.end() ? it->second : id;
  };
  std::map<std::pair<int, int>, bool> merged;  // (a, c), a < c -> one_line's verdict
  FeatureCovariance covariance;
  const std::map<int, std::vector<int>> frames_of = track_frames(*b);
  const auto same_line = [&](int a, int c) {
    if (tracker(a) == tracker(c)) return true;
    if (!(merge_chi2 > 0.0) || share_a_frame(frames_of.at(a), frames_of.at(c))) return false;
    const auto key = std::minmax(a, c);
    const auto it = merged.find(key);
    if (it != merged.end()) return it->second;
    return merged[key] = one_line(b, a, c, merge_chi2, &covariance);
  };
  std::set<BearingKey> crossing;  // (track id, frame)
  for (int k = 0; k < frames; ++k)
    for (int id :
         crowded_directions(std::move(seen[static_cast<std::size_t>(k)]), guard, same_line))
      crossing.insert({id, k});
  if (crossing.empty()) return 0;
  const int n = filter_bearings(b, [&](ceres::ResidualBlockId id, const BearingKey& key) {
    if (!crossing.count(key)) return true;
    b->problem->RemoveResidualBlock(id);
    b->guarded.push_back(key);
    return false;
  });
  if (n > 0) drop_unobserved_features(b, min_bearings);
  return n;
}

}  // namespace omnivert::calib::internal
