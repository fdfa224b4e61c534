#include "omnivert/match/matcher.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>

namespace omnivert {

bool MatchOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  // Descriptor distances are non-negative; a non-positive bound would reject everything.
  if (!(std::isfinite(f1) && f1 > 0.0)) return fail("F1 must be a positive number (Table 2: 1.05)");
  // F2 and F3 "clearly range from zero to one" (Sec. 4.2, 4.3).
  if (!(f2 > 0.0 && f2 <= 1.0)) return fail("F2 must be in (0, 1] (Table 2: 0.75)");
  if (!(f3 > 0.0 && f3 <= 1.0)) return fail("F3 must be in (0, 1] (Table 2: 0.8)");
  if (!(partial_area_scale == 0.0 ||
        (partial_area_scale >= 1.0 && std::isfinite(partial_area_scale))))
    return fail("the partial-area scale must be 0 (off) or a finite number >= 1");
  if (!(partial_side_scale == 0.0 ||
        (partial_side_scale >= 1.0 && std::isfinite(partial_side_scale))))
    return fail("the partial-side scale must be 0 (off) or a finite number >= 1");
  return true;
}

const char* to_string(MatchVerdict v) {
  switch (v) {
    case MatchVerdict::kAccepted:
      return "accepted";
    case MatchVerdict::kNoCandidates:
      return "no candidates";
    case MatchVerdict::kFailedTest1:
      return "failed test 1";
    case MatchVerdict::kFailedTest2:
      return "failed test 2";
    case MatchVerdict::kFailedTest3:
      return "failed test 3";
  }
  return "?";
}

MatchVerdict apply_match_tests(const MatchOptions& options,
                               int num_candidates,
                               double min_distance,
                               double second_distance,
                               double mean_distance) {
  if (num_candidates <= 0) return MatchVerdict::kNoCandidates;
  // Sec. 4.1, eq. (8).
  if (options.use_test1 && !(min_distance <= options.f1)) return MatchVerdict::kFailedTest1;
  // Sec. 4.2, eq. (9); with one candidate the mean is the minimum itself, so this rejects
  // every non-zero distance (see the header).
  if (options.use_test2 && !(min_distance <= options.f2 * mean_distance)) {
    return MatchVerdict::kFailedTest2;
  }
  // Sec. 4.3, eq. (10); second_distance is +inf for a single candidate (vacuous test).
  if (options.use_test3 && num_candidates >= 2 && !(min_distance <= options.f3 * second_distance)) {
    return MatchVerdict::kFailedTest3;
  }
  return MatchVerdict::kAccepted;
}

Matcher::Matcher(MatchOptions options) : options_(options) {}

Matcher::DistanceView Matcher::compute_distances(const ConstDescriptors& query,
                                                 const ConstDescriptors& candidates) {
  assert(query.rows() == 0 || candidates.rows() == 0 || query.cols() == candidates.cols());
  rows_ = query.rows();
  cols_ = candidates.rows();
  // Grow the work space only when a larger problem arrives (no allocation in steady state).
  if (distances_.rows() < rows_ || distances_.cols() < cols_) {
    // Generous steps (at least 64, then doubling) so that growth stops after a few frames.
    auto grow = [](Eigen::Index have, Eigen::Index need) {
      return have >= need ? have : std::max<Eigen::Index>({need, 2 * have, 64});
    };
    distances_.resize(grow(distances_.rows(), rows_), grow(distances_.cols(), cols_));
  }
  if (query_norms_.size() < rows_) query_norms_.resize(distances_.rows());
  if (candidate_norms_.size() < cols_) candidate_norms_.resize(distances_.cols());
  if (rows_ == 0 || cols_ == 0) return last_distances();

  if (options_.partial_side_scale > 0.0 && query.cols() % 6 == 0)
    return partial_side_distances(query, candidates);
  if (options_.partial_area_scale > 0.0 && query.cols() % 3 == 0)
    return partial_distances(query, candidates);
  // Eq. (6) as |a - b|^2 = |a|^2 + |b|^2 - 2 a.b: one matrix product for all pairs.
  auto d = distances_.topLeftCorner(rows_, cols_);
  d.noalias() = query * candidates.transpose();
  query_norms_.head(rows_) = query.rowwise().squaredNorm();
  candidate_norms_.head(cols_) = candidates.rowwise().squaredNorm();
  for (Eigen::Index i = 0; i < rows_; ++i) {
    const float qn = query_norms_(i);
    for (Eigen::Index j = 0; j < cols_; ++j) {
      // Rounding can make the expansion slightly negative for near-identical descriptors.
      const float sq = qn + candidate_norms_(j) - 2.0f * d(i, j);
      d(i, j) = std::sqrt(std::max(sq, 0.0f));
    }
  }
  return last_distances();
}

namespace {

// MatchOptions::partial_area_scale's rule on the areas' squared distances: their sum, or s
// times the sum without the largest where that is less.
float occluder_tolerant_sq(float sum, float worst, float s) {
  return std::min(sum, s * (sum - worst));
}

// With MatchOptions::partial_side_scale too: also s_side times the lesser side's d^2.
template <typename T>
T side_tolerant_sq(T sum, T worst, T left, T right, T area_scale, T side_scale) {
  T d = sum;
  if (area_scale > 0) d = std::min(d, area_scale * (sum - worst));
  return std::min(d, side_scale * std::min(left, right));
}

}  // namespace

// out = the squared distances over the columns at..at+width of every query and candidate row,
// |a|^2 + |b|^2 - 2 a.b by one matrix product (clamped at 0 against rounding).
void Matcher::block_distances_sq(const ConstDescriptors& query,
                                 const ConstDescriptors& candidates,
                                 Eigen::Index at,
                                 Eigen::Index width,
                                 Eigen::Block<DistanceMatrix> out) {
  const auto q = query.middleCols(at, width);
  const auto c = candidates.middleCols(at, width);
  out.noalias() = q * c.transpose();
  query_norms_.head(rows_) = q.rowwise().squaredNorm();
  candidate_norms_.head(cols_) = c.rowwise().squaredNorm();
  for (Eigen::Index i = 0; i < rows_; ++i)
    for (Eigen::Index j = 0; j < cols_; ++j)
      out(i, j) = std::max(query_norms_(i) + candidate_norms_(j) - 2.0f * out(i, j), 0.0f);
}

// MatchOptions::partial_area_scale: per area k, d_k^2 = |a_k|^2 + |b_k|^2 - 2 a_k.b_k by one
// matrix product over its third of the columns; their sum in distances_, their largest in
// worst_.
Matcher::DistanceView Matcher::partial_distances(const ConstDescriptors& query,
                                                 const ConstDescriptors& candidates) {
  if (area_.rows() < distances_.rows() || area_.cols() < distances_.cols()) {
    area_.resize(distances_.rows(), distances_.cols());
    worst_.resize(distances_.rows(), distances_.cols());
  }
  auto d = distances_.topLeftCorner(rows_, cols_);
  auto a = area_.topLeftCorner(rows_, cols_);
  auto m = worst_.topLeftCorner(rows_, cols_);
  const Eigen::Index w = query.cols() / 3;
  for (Eigen::Index k = 0; k < 3; ++k) {
    block_distances_sq(query, candidates, k * w, w, a);
    for (Eigen::Index i = 0; i < rows_; ++i)
      for (Eigen::Index j = 0; j < cols_; ++j) {
        const float sq = a(i, j);
        d(i, j) = k == 0 ? sq : d(i, j) + sq;
        m(i, j) = k == 0 ? sq : std::max(m(i, j), sq);
      }
  }
  const float s = static_cast<float>(options_.partial_area_scale);
  for (Eigen::Index i = 0; i < rows_; ++i)
    for (Eigen::Index j = 0; j < cols_; ++j)
      d(i, j) = std::sqrt(occluder_tolerant_sq(d(i, j), m(i, j), s));
  return last_distances();
}

// MatchOptions::partial_side_scale: the six halves' d^2 by one matrix product each (columns
// in sixths: H_1L, H_1R, H_2L, ...), summed per area (sum, largest) and per side.
Matcher::DistanceView Matcher::partial_side_distances(const ConstDescriptors& query,
                                                      const ConstDescriptors& candidates) {
  for (DistanceMatrix* m : {&area_, &worst_, &half_, &left_, &right_})
    if (m->rows() < distances_.rows() || m->cols() < distances_.cols())
      m->resize(distances_.rows(), distances_.cols());
  auto d = distances_.topLeftCorner(rows_, cols_);
  auto a = area_.topLeftCorner(rows_, cols_);
  auto m = worst_.topLeftCorner(rows_, cols_);
  auto h = half_.topLeftCorner(rows_, cols_);
  auto l = left_.topLeftCorner(rows_, cols_);
  auto r = right_.topLeftCorner(rows_, cols_);
  const Eigen::Index w = query.cols() / 6;
  for (Eigen::Index k = 0; k < 6; ++k) {
    block_distances_sq(query, candidates, k * w, w, h);
    const bool right = k % 2 == 1;
    for (Eigen::Index i = 0; i < rows_; ++i)
      for (Eigen::Index j = 0; j < cols_; ++j) {
        const float sq = h(i, j);
        if (!right) {
          a(i, j) = sq;
          l(i, j) = k == 0 ? sq : l(i, j) + sq;
          continue;
        }
        a(i, j) += sq;
        r(i, j) = k == 1 ? sq : r(i, j) + sq;
        d(i, j) = k == 1 ? a(i, j) : d(i, j) + a(i, j);
        m(i, j) = k == 1 ? a(i, j) : std::max(m(i, j), a(i, j));
      }
  }
  const auto sa = static_cast<float>(options_.partial_area_scale);
  const auto ss = static_cast<float>(options_.partial_side_scale);
  for (Eigen::Index i = 0; i < rows_; ++i)
    for (Eigen::Index j = 0; j < cols_; ++j)
      d(i, j) = std::sqrt(side_tolerant_sq(d(i, j), m(i, j), l(i, j), r(i, j), sa, ss));
  return last_distances();
}

float descriptor_distance_sq(const MatchOptions& o,
                             const Eigen::Ref<const Eigen::RowVectorXf>& a,
                             const Eigen::Ref<const Eigen::RowVectorXf>& b) {
  const Eigen::Index n = a.size();
  if (o.partial_side_scale > 0.0 && n % 6 == 0) {
    const Eigen::Index w = n / 6;
    float sum = 0.0f, worst = 0.0f, side[2] = {0.0f, 0.0f};
    for (Eigen::Index k = 0; k < 3; ++k) {
      float area = 0.0f;
      for (Eigen::Index s = 0; s < 2; ++s) {
        const Eigen::Index at = (2 * k + s) * w;
        const float sq = (a.segment(at, w) - b.segment(at, w)).squaredNorm();
        area += sq;
        side[s] += sq;
      }
      sum += area;
      worst = std::max(worst, area);
    }
    return side_tolerant_sq(sum,
                            worst,
                            side[0],
                            side[1],
                            static_cast<float>(o.partial_area_scale),
                            static_cast<float>(o.partial_side_scale));
  }
  if (!(o.partial_area_scale > 0.0) || n % 3 != 0) return (a - b).squaredNorm();
  const Eigen::Index w = n / 3;
  float sum = 0.0f, worst = 0.0f;
  for (Eigen::Index k = 0; k < 3; ++k) {
    const float sq = (a.segment(k * w, w) - b.segment(k * w, w)).squaredNorm();
    sum += sq;
    worst = std::max(worst, sq);
  }
  return occluder_tolerant_sq(sum, worst, static_cast<float>(o.partial_area_scale));
}

MatchResult Matcher::evaluate_row(const Eigen::Ref<const Eigen::RowVectorXf>& row) const {
  MatchResult r;
  const Eigen::Index n = row.size();
  if (n == 0) return r;
  float best = std::numeric_limits<float>::infinity();
  float second = std::numeric_limits<float>::infinity();
  int best_j = -1;
  double sum = 0.0;
  for (Eigen::Index j = 0; j < n; ++j) {
    const float v = row(j);
    sum += v;
    if (v < best) {  // strict: ties keep the lowest index
      second = best;
      best = v;
      best_j = static_cast<int>(j);
    } else if (v < second) {
      second = v;
    }
  }
  r.best = best_j;
  r.min_distance = best;
  r.second_distance = second;
  r.mean_distance = static_cast<float>(sum / static_cast<double>(n));
  r.verdict =
      apply_match_tests(options_, static_cast<int>(n), best, second, sum / static_cast<double>(n));
  return r;
}

void Matcher::match(const ConstDescriptors& query,
                    const ConstDescriptors& candidates,
                    std::vector<MatchResult>* results) {
  const DistanceView d = compute_distances(query, candidates);
  results->resize(static_cast<std::size_t>(query.rows()));
  for (Eigen::Index i = 0; i < query.rows(); ++i) {
    (*results)[static_cast<std::size_t>(i)] = cols_ == 0 ? MatchResult{} : evaluate_row(d.row(i));
  }
}

std::vector<MatchResult> match_brute_force(const MatchOptions& options,
                                           const DescriptorMatrix& query,
                                           const DescriptorMatrix& candidates) {
  std::vector<MatchResult> out(static_cast<std::size_t>(query.rows()));
  const Eigen::Index nb = candidates.rows();
  std::vector<std::pair<double, int>> row;
  for (Eigen::Index i = 0; i < query.rows(); ++i) {
    row.clear();
    double sum = 0.0;
    for (Eigen::Index j = 0; j < nb; ++j) {
      // Eq. (6) term by term, per area when the occluder-tolerant distance is on.
      const Eigen::Index cols = query.cols();
      const bool partial = options.partial_area_scale > 0.0 && cols % 3 == 0;
      const bool sides = options.partial_side_scale > 0.0 && cols % 6 == 0;
      double area[3] = {0.0, 0.0, 0.0}, side[2] = {0.0, 0.0};
      for (Eigen::Index k = 0; k < cols; ++k) {
        const double diff = static_cast<double>(query(i, k)) - candidates(j, k);
        area[partial || sides ? 3 * k / cols : 0] += diff * diff;
        if (sides) side[(6 * k / cols) % 2] += diff * diff;
      }
      const double s = area[0] + area[1] + area[2];
      const double worst = std::max({area[0], area[1], area[2]});
      const double dist =
          std::sqrt(sides     ? side_tolerant_sq(s,
                                             worst,
                                             side[0],
                                             side[1],
                                             options.partial_area_scale,
                                             options.partial_side_scale)
                    : partial ? std::min(s, options.partial_area_scale * (s - worst))
                              : s);
      sum += dist;
      row.emplace_back(dist, static_cast<int>(j));
    }
    MatchResult& r = out[static_cast<std::size_t>(i)];
    if (nb == 0) continue;
    std::stable_sort(
        row.begin(), row.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    r.best = row[0].second;
    r.min_distance = static_cast<float>(row[0].first);
    const double second = nb >= 2 ? row[1].first : std::numeric_limits<double>::infinity();
    r.second_distance = static_cast<float>(second);
    const double mean = sum / static_cast<double>(nb);
    r.mean_distance = static_cast<float>(mean);
    r.verdict = apply_match_tests(options, static_cast<int>(nb), row[0].first, second, mean);
  }
  return out;
}

}  // namespace omnivert
