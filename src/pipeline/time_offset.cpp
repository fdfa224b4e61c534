#include "omnivert/pipeline/time_offset.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>

#include <Eigen/Geometry>

#include "core/parallel.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::pipeline {

bool TimeOffsetOptions::IsValid(std::string* why) const {
  const auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  const auto non_negative = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!positive(max_offset_s) || !positive(step_s) || step_s > max_offset_s)
    return fail("max_offset_s and step_s must be > 0 [s], step_s at most max_offset_s");
  if (min_common_tracks < 1 || min_pairs < 1)
    return fail("min_common_tracks and min_pairs must be >= 1");
  if (!positive(max_sigma_s)) return fail("max_sigma_s must be > 0 [s]");
  if (jackknife_block < 0) return fail("jackknife_block must be >= 0 (0: no jackknife)");
  if (threads < 0) return fail("threads must be >= 0 (0: every core)");
  if (!non_negative(min_rise) || !non_negative(significance) || !non_negative(min_applied_s))
    return fail("min_rise, significance and min_applied_s must be >= 0");
  return true;
}

namespace {

// theta_w(t): the wheels' heading, linear between samples, held beyond the ends.
double heading_at(const std::vector<double>& t, const std::vector<double>& h, double x) {
  if (x <= t.front()) return h.front();
  if (x >= t.back()) return h.back();
  const auto it = std::upper_bound(t.begin(), t.end(), x);
  const std::size_t b = static_cast<std::size_t>(it - t.begin()), a = b - 1;
  const double f = (x - t[a]) / (t[b] - t[a]);
  return h[a] + f * (h[b] - h[a]);
}

double median(std::vector<double> v);

// The triples of pairs (i-1, i, i+1), by the middle image i, and the lines spanning them.
struct Triple {
  std::size_t i = 0;
  std::vector<Eigen::Vector3d> b;  // per line, its turns over the three pairs
};

struct Problem {
  const TimeOffsetInput& in;
  std::vector<Triple> triples;
  std::vector<std::size_t> used;  // indices into triples

  // The wheels' (d_theta, d_rho) between the images j-1 and j stamped late by S, and the
  // variance of d_theta under eq. (31): K (|d_R| + |d_L|) / e^2, with |d_R| + |d_L| from the
  // turn and the travel (2 max(|d_rho|, |d_theta| e / 2)).
  Eigen::Vector3d wheel_step(std::size_t j, double S) const {
    const double a = in.image_t[j - 1] - S, b = in.image_t[j] - S;
    const double dth =
        heading_at(in.wheel_t, in.wheel_heading, b) - heading_at(in.wheel_t, in.wheel_heading, a);
    const double drho =
        heading_at(in.wheel_t, in.wheel_distance, b) - heading_at(in.wheel_t, in.wheel_distance, a);
    const double e = in.wheel_base;
    const double wheels = 2.0 * std::max(std::abs(drho), 0.5 * std::abs(dth) * e);
    return {dth, drho, in.odometry_k * wheels / (e * e)};
  }
  // e(i, S)^2 / sigma_i(S)^2: e(i, S) the median over the triple's lines of
  // |P b_j|, P = I - A (A^T A)^-1 A^T the projection away from the wheels' columns A
  // (d_theta, d_rho over the three pairs; by Gram-Schmidt, a column the wheels leave at zero is
  // no direction), sigma_i^2 = trace(P Sigma P) with Sigma the noise of the three turns: the
  // wheels' d_theta (eq. 31, common to every line) and two bearings per turn.
  double weighted_residual(const Triple& t, double S) const {
    Eigen::Vector3d theta, rho;
    Eigen::Matrix3d Sigma = Eigen::Matrix3d::Zero();
    const double sb2 = in.bearing_sigma * in.bearing_sigma;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d w = wheel_step(t.i - 1 + static_cast<std::size_t>(k), S);
      theta(k) = w(0), rho(k) = w(1);
      Sigma(k, k) = w(2) + 2.0 * sb2;
      if (k > 0) Sigma(k, k - 1) = Sigma(k - 1, k) = -sb2;  // the image the two turns share
    }
    std::vector<Eigen::Vector3d> basis;
    for (Eigen::Vector3d a : {theta, rho}) {
      const double scale = a.norm();
      for (const Eigen::Vector3d& u : basis) a -= u.dot(a) * u;
      if (a.norm() > 1e-9 && a.norm() > 1e-6 * scale) basis.push_back(a.normalized());
    }
    Eigen::Matrix3d P = Eigen::Matrix3d::Identity();
    for (const Eigen::Vector3d& u : basis) P -= u * u.transpose();
    std::vector<double> e;
    e.reserve(t.b.size());
    for (const Eigen::Vector3d& b : t.b) e.push_back((P * b).norm());
    const double var = (P * Sigma * P).trace();
    return var > 0 ? std::pow(median(std::move(e)), 2) / var : 0.0;
  }
  // The sandwich variance of the minimiser S* of J = sum_i q_i (q_i the weighted residual of
  // triple i), with the slopes g_i and the curvature J'' taken over +-h:
  //   var(S*) = sum_{i, k sharing an image} g_i g_k / J''^2.
  // The model's 1 / a counts every triple as independent, but triples i and k share the
  // wheels' noise of their common pairs (|i - k| <= 2) and the bearings of their common images
  // (triple i spans images i-2 .. i+1: |i - k| <= 3), and the few triples
  // where the motion changes carry nearly all the information; the sandwich takes both, and
  // the residuals as they are rather than as modelled.
  double sandwich_variance(double S, double h) const {
    std::vector<std::pair<std::size_t, double>> g;  // (middle image, slope)
    double curvature = 0;
    for (std::size_t k : used) {
      const double qp = weighted_residual(triples[k], S + h);
      const double q0 = weighted_residual(triples[k], S);
      const double qm = weighted_residual(triples[k], S - h);
      g.emplace_back(triples[k].i, (qp - qm) / (2 * h));
      curvature += (qp - 2 * q0 + qm) / (h * h);
    }
    double num = 0;
    for (std::size_t a = 0; a < g.size(); ++a)
      for (std::size_t b = a; b < g.size() && g[b].first <= g[a].first + 3; ++b)
        num += (a == b ? 1.0 : 2.0) * g[a].second * g[b].second;
    return curvature > 0 ? std::max(num, 0.0) / (curvature * curvature) : INFINITY;
  }
};

struct Minimum {
  double S = 0, cost = 0, curvature = 0;  // J ~ cost + curvature (s - S)^2
  double rise = 0;                        // the median of J over the grid minus the minimum
};

// The minimum of J sampled on the grid S_k = (k - half) step, refined by the parabola through
// it and its two neighbours.
Minimum grid_minimum(const std::vector<double>& J, double step) {
  const double half = static_cast<double>(J.size() / 2);
  const std::size_t best =
      static_cast<std::size_t>(std::min_element(J.begin(), J.end()) - J.begin());
  Minimum m;
  m.S = (static_cast<double>(best) - half) * step;
  m.cost = J[best];
  m.rise = median(J) - J[best];
  if (best > 0 && best + 1 < J.size()) {
    const double jm = J[best - 1], j0 = J[best], jp = J[best + 1];
    const double c2 = (jp + jm - 2 * j0) / (2 * step * step);  // curvature a
    if (c2 > 0) {
      const double shift = (jm - jp) / (4 * c2 * step);  // the parabola's vertex
      m.S += shift;
      m.cost = j0 - c2 * shift * shift;
      m.curvature = c2;
    }
  }
  return m;
}

// J on the grid, kept per block of `block` consecutive triples (one block: all of them).
std::vector<std::vector<double>> block_costs(const Problem& p,
                                             const TimeOffsetOptions& o,
                                             std::size_t block) {
  const int half = static_cast<int>(std::lround(o.max_offset_s / o.step_s));
  const std::size_t blocks = (p.used.size() + block - 1) / block;
  std::vector<std::vector<double>> J(blocks, std::vector<double>(2 * half + 1, 0.0));
  // One grid point per call: its sums in the triples' order, whichever thread takes it.
  parallel_for(
      static_cast<std::size_t>(2 * half + 1), resolve_threads(o.threads), [&](std::size_t g, int) {
        const double S = (static_cast<int>(g) - half) * o.step_s;
        for (std::size_t u = 0; u < p.used.size(); ++u)
          J[u / block][g] += p.weighted_residual(p.triples[p.used[u]], S);
      });
  return J;
}

// The delete-a-block jackknife's variance of the minimiser: each block of consecutive
// triples left out in turn, var = (m - 1) / m sum_b (S_(-b) - mean)^2. The few triples where
// the motion changes carry S; when one change carries it all, leaving it out leaves J without
// a minimum, and the variance says so, which neither the model nor the sandwich can.
double jackknife_variance(const std::vector<std::vector<double>>& blocks,
                          const std::vector<double>& J,
                          double step) {
  const std::size_t m = blocks.size();
  if (m < 2) return INFINITY;
  std::vector<double> S(m);
  std::vector<double> without(J.size());
  for (std::size_t b = 0; b < m; ++b) {
    for (std::size_t k = 0; k < J.size(); ++k) without[k] = J[k] - blocks[b][k];
    S[b] = grid_minimum(without, step).S;
  }
  double mean = 0, ss = 0;
  for (double s : S) mean += s / static_cast<double>(m);
  for (double s : S) ss += (s - mean) * (s - mean);
  return static_cast<double>(m - 1) / static_cast<double>(m) * ss;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

std::string fmt_g(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

bool TimeOffsetOptions::significant(double offset_s, double sigma_s) const {
  return std::abs(offset_s) > significance * sigma_s && std::abs(offset_s) >= min_applied_s;
}

bool TimeOffsetEstimate::significant(const TimeOffsetOptions& o) const {
  return determined && o.significant(offset_s, sigma_s);
}

TimeOffsetEstimate estimate_time_offset(const TimeOffsetInput& in, const TimeOffsetOptions& o) {
  TimeOffsetEstimate e;
  Problem p{in, {}, {}};
  // The triples: lines seen in the four images i-2 .. i+1, inside the wheel data for every
  // S searched (the set must not change with S).
  for (std::size_t i = 2; i + 1 < in.image_t.size() && i + 1 < in.turns.size(); ++i) {
    if (in.wheel_t.empty() || in.image_t[i - 2] - o.max_offset_s < in.wheel_t.front() ||
        in.image_t[i + 1] + o.max_offset_s > in.wheel_t.back())
      continue;
    Triple t;
    t.i = i;
    for (const auto& [id, turn] : in.turns[i]) {
      auto find = [&](std::size_t j) {
        const auto& v = in.turns[j];
        const auto it = std::lower_bound(
            v.begin(), v.end(), id, [](const auto& x, std::int64_t y) { return x.first < y; });
        return it != v.end() && it->first == id ? it->second : NAN;
      };
      const Eigen::Vector3d b(find(i - 1), turn, find(i + 1));
      if (b.allFinite()) t.b.push_back(b);
    }
    if (static_cast<int>(t.b.size()) >= o.min_common_tracks) p.triples.push_back(std::move(t));
  }
  for (std::size_t k = 0; k < p.triples.size(); ++k) p.used.push_back(k);
  if (in.wheel_t.size() < 2 || static_cast<int>(p.used.size()) < o.min_pairs) {
    e.why = "too few image pairs with " + std::to_string(o.min_common_tracks) +
            " or more lines tracked through them (" + std::to_string(p.used.size()) + ")";
    return e;
  }
  // A line that changed line or crossed another has a wrong turn: the median over the lines
  // of each triple leaves it out.
  const std::size_t block =
      o.jackknife_block > 0 ? static_cast<std::size_t>(o.jackknife_block) : p.used.size();
  const std::vector<std::vector<double>> blocks = block_costs(p, o, block);
  std::vector<double> J(blocks.front().size(), 0.0);
  for (const auto& b : blocks)
    for (std::size_t k = 0; k < J.size(); ++k) J[k] += b[k];
  const Minimum m = grid_minimum(J, o.step_s);
  e.pairs = static_cast<int>(p.used.size());
  e.offset_s = m.S;
  // J is weighted by the noise model, so sigma_S^2 = 1 / a; s^2 = J_min / (n - 1) above 1
  // (more noise than eq. 31 and the bearing sigma say) scales it up. Below 1 it is not
  // trusted: most triples' residuals lose their noise to the fit of k_j and c_j.
  const double s2 = std::max(m.cost, 0.0) / (e.pairs - 1);
  e.residual_scale = std::sqrt(s2);
  e.sigma_s = m.curvature > 0 ? std::sqrt(std::max(s2, 1.0) / m.curvature) : INFINITY;
  // The model's sigma is a floor: the sandwich may only widen it (too few triples carry S for
  // their spread to be trusted below the model).
  if (std::isfinite(e.sigma_s) && o.sigma_step_s > 0)
    e.sigma_s = std::max(e.sigma_s, std::sqrt(p.sandwich_variance(m.S, o.sigma_step_s)));
  // Whether the run tells S at all is the model's and the sandwich's say (the refinement then
  // estimates it with the extrinsics); the jackknife only widens the sigma reported, and so
  // keeps a single change of motion from shifting the stamps before tracking.
  const double told_sigma = e.sigma_s;
  if (std::isfinite(e.sigma_s) && o.jackknife_block > 0)
    e.sigma_s = std::max(e.sigma_s, std::sqrt(jackknife_variance(blocks, J, o.step_s)));
  if (!(m.curvature > 0) || std::abs(m.S) >= o.max_offset_s - o.step_s) {
    e.why = "no minimum inside +-" + std::to_string(o.max_offset_s) + " s";
  } else if (!(told_sigma <= o.max_sigma_s) || !(m.rise >= o.min_rise * std::max(s2, 1.0))) {
    e.why = "the run has too few turns starting or ending to tell it";
  } else {
    e.determined = true;
  }
  return e;
}

TimeOffsetEstimate estimate_time_offset(const dataset::Dataset& data,
                                        const std::vector<TrackRow>& rows,
                                        double odometry_k,
                                        double bearing_sigma,
                                        const TimeOffsetOptions& o) {
  const auto& images = data.images();
  const auto& wheel = data.wheel();
  const double e = data.wheel_sensor().wheel_base;
  if (wheel.size() < 2 || !(e > 0)) {
    TimeOffsetEstimate none;
    none.why = "no wheel data with a wheel base";
    return none;
  }
  // Bearings per frame and track; a track holding two lines of a frame is left out there.
  std::vector<std::map<std::int64_t, double>> seen(images.size());
  std::vector<std::map<std::int64_t, int>> count(images.size());
  for (const TrackRow& r : rows) {
    if (r.frame < 0 || static_cast<std::size_t>(r.frame) >= images.size()) continue;
    seen[static_cast<std::size_t>(r.frame)][r.track_id] = r.bearing;
    ++count[static_cast<std::size_t>(r.frame)][r.track_id];
  }
  const std::int64_t t0 = wheel.front().timestamp_ns;
  TimeOffsetInput in;
  in.wheel_base = e;
  in.odometry_k = odometry_k;
  in.bearing_sigma = bearing_sigma;
  in.turns.resize(images.size());
  for (std::size_t i = 0; i < images.size(); ++i) {
    in.image_t.push_back(static_cast<double>(images[i].timestamp_ns - t0) * 1e-9);
    if (i == 0) continue;
    for (const auto& [id, beta] : seen[i]) {
      const auto prev = seen[i - 1].find(id);
      if (prev == seen[i - 1].end() || count[i].at(id) > 1 || count[i - 1].at(id) > 1) continue;
      in.turns[i].emplace_back(id, -angle_diff(beta, prev->second));  // -d_beta (map order)
    }
  }
  for (const auto& w : wheel) {
    in.wheel_t.push_back(static_cast<double>(w.timestamp_ns - t0) * 1e-9);
    in.wheel_heading.push_back((w.travel.right - w.travel.left) / e);  // eq. (15)
    in.wheel_distance.push_back(0.5 * (w.travel.right + w.travel.left));
  }
  return estimate_time_offset(in, o);
}

std::string time_offset_line(const TimeOffsetEstimate& e,
                             bool given,
                             bool applied,
                             const TimeOffsetOptions& o) {
  char buf[600];
  if (given) {
    std::snprintf(
        buf, sizeof buf, "time offset: image stamps late by %.1f ms (given)", e.offset_s * 1e3);
  } else if (e.refined) {
    const bool tracks_applied = e.retracked ? e.tracks_applied : applied;
    std::string before = tracks_applied ? "applied before tracking"
                                        : "not applied before tracking (applied above " +
                                              fmt_g(o.significance) + " sigma and " +
                                              fmt_g(o.min_applied_s * 1e3) + " ms)";
    if (e.retracked)
      before += "; the refinement's first estimate, " +
                fmt_g(std::round(e.retracked_s * 1e4) / 10) +
                " ms, applied and the images tracked again";
    std::snprintf(buf,
                  sizeof buf,
                  "time offset: image stamps late by %.1f +- %.1f ms (refined with the "
                  "extrinsics; from the tracks %.1f +- %.1f ms over %d image pairs, %s)",
                  e.offset_s * 1e3,
                  e.sigma_s * 1e3,
                  e.tracks_offset_s * 1e3,
                  e.tracks_sigma_s * 1e3,
                  e.pairs,
                  before.c_str());
  } else if (!e.determined) {
    std::snprintf(buf, sizeof buf, "time offset: not determined (%s); none applied", e.why.c_str());
  } else {
    std::snprintf(buf,
                  sizeof buf,
                  "time offset: image stamps late by %.1f +- %.1f ms (from %d image pairs); %s",
                  e.offset_s * 1e3,
                  e.sigma_s * 1e3,
                  e.pairs,
                  applied ? "applied"
                          : ("not applied (applied above " + fmt_g(o.significance) + " sigma and " +
                             fmt_g(o.min_applied_s * 1e3) + " ms)")
                                .c_str());
  }
  return buf;
}

}  // namespace omnivert::pipeline
