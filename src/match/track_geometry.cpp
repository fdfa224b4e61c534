#include "omnivert/match/track_geometry.hpp"

#include <algorithm>

#include "omnivert/core/angles.hpp"

namespace omnivert {
namespace {

int bin_of(double angle) {
  const double a = wrap_positive(angle);  // [0, 2 pi)
  return std::min(CameraYawVotes::kBins - 1,
                  static_cast<int>(a / (2.0 * kPi) * CameraYawVotes::kBins));
}

}  // namespace

void CameraYawVotes::add(double bearing, double change, double min_change) {
  if (!(std::abs(change) > min_change) || !std::isfinite(bearing)) return;
  // sin(bearing + yaw) > 0 for change > 0: yaw in (-bearing, pi - bearing); the other half
  // circle for change < 0.
  const double start = change > 0 ? -bearing : kPi - bearing;
  const int a = bin_of(start);
  const int half = kBins / 2;
  if (a + half <= kBins) {
    ++diff_[static_cast<std::size_t>(a)];
    --diff_[static_cast<std::size_t>(a + half)];
  } else {  // wraps around
    ++diff_[static_cast<std::size_t>(a)];
    --diff_[kBins];
    ++diff_[0];
    --diff_[static_cast<std::size_t>(a + half - kBins)];
  }
  ++pairs_;
}

double CameraYawVotes::estimate(int min_pairs, double max_spread) const {
  if (pairs_ < min_pairs) return NAN;
  std::array<int, kBins> votes{};
  int run = 0, best = 0;
  for (int b = 0; b < kBins; ++b) {
    run += diff_[static_cast<std::size_t>(b)];
    votes[static_cast<std::size_t>(b)] = run;
    best = std::max(best, run);
  }
  // The bins within 2 sqrt(pairs) votes of the most agreed one, around it: the count falls
  // off linearly with the distance from the true yaw (the pairs whose boundary lies in
  // between), so that arc shrinks as 1 / sqrt(pairs); a lone bin at the maximum can be noise.
  const int tolerance = static_cast<int>(2.0 * std::sqrt(static_cast<double>(pairs_)));
  int peak = 0;
  while (votes[static_cast<std::size_t>(peak)] != best) ++peak;
  int lo = 0, hi = 0;  // the arc is [peak - lo, peak + hi]
  auto at = [&](int b) { return votes[static_cast<std::size_t>(((b % kBins) + kBins) % kBins)]; };
  while (lo < kBins && at(peak - lo - 1) >= best - tolerance) ++lo;
  while (hi < kBins && at(peak + hi + 1) >= best - tolerance) ++hi;
  const int best_len = lo + hi + 1, best_start = peak - lo;
  if (best_len >= kBins || best_len * 2.0 * kPi / kBins > max_spread) return NAN;
  const double middle = (best_start + 0.5 * best_len) * 2.0 * kPi / kBins;
  return wrap_angle(middle);
}

bool intersect_rays(double x0,
                    double y0,
                    double dir0,
                    double x1,
                    double y1,
                    double dir1,
                    double min_angle,
                    double* x,
                    double* y) {
  const double c0 = std::cos(dir0), s0 = std::sin(dir0), c1 = std::cos(dir1), s1 = std::sin(dir1);
  const double det = c1 * s0 - c0 * s1;  // sin(dir0 - dir1)
  if (!(std::abs(det) >= std::sin(min_angle))) return false;
  // (x0, y0) + t0 (c0, s0) = (x1, y1) + t1 (c1, s1), by Cramer's rule.
  const double dx = x1 - x0, dy = y1 - y0;
  const double t0 = (dx * (-s1) + c1 * dy) / (c0 * (-s1) + c1 * s0);
  const double t1 = (c0 * dy - s0 * dx) / (c0 * (-s1) + c1 * s0);
  if (!(t0 > 0.0 && t1 > 0.0)) return false;
  *x = x0 + t0 * c0;
  *y = y0 + t0 * s0;
  return true;
}

}  // namespace omnivert
