#include "omnivert/calib/flow_yaw.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "omnivert/calib/model.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

double camera_yaw_from_flow(const CalibrationRun& run,
                            double wheel_base,
                            int min_pairs,
                            double min_explained) {
  // Each bearing pair of one track in consecutive frames: d_alpha = d_beta + d_theta (the
  // world direction's change, the wheels' turn put back; eq. 30), against the signed distance
  // driven ds. Along a straight, a point at distance h from the line of travel turns at
  // d_alpha / ds = sin(x) |sin(x)| / h, x = beta + yaw its bearing from the direction of
  // travel (which is at -yaw in the camera's frame). For a given yaw each track's 1/h on each
  // straight is a one-dimensional least-squares fit; the yaw is the one whose fits explain the
  // most of sum(d_alpha^2): a grid of 0.5 degree, then a parabola through the best three.
  // (Without 1/h, one sum over all tracks leaned by 0.27 rad on the synthetic paper run; with
  // 1/|d| instead of 1/h, by 0.25.)
  struct Pair {
    double ds, dalpha, sin_beta, cos_beta;  // beta: the pair's mid bearing
  };
  std::map<std::pair<int, int>, std::vector<Pair>> tracks;  // (track id, straight) -> pairs
  double total = 0.0;
  int pairs = 0;
  int straight = 0;  // counts the frames that turn: a track's h is that of one straight
  std::map<int, double> previous;  // track id -> bearing in the previous frame
  for (const FrameInput& f : run.frames) {
    const Vec2 step = wheel_step(f.d_right, f.d_left, wheel_base);  // eq. (15)
    const double ds = step(0), dtheta = step(1);
    if (std::abs(dtheta) * wheel_base > std::abs(ds)) ++straight;  // wheels turning, not driving
    std::map<int, double> now;
    for (const BearingObservation& o : f.observations) {
      now[o.track_id] = o.beta;
      const auto it = previous.find(o.track_id);
      if (it == previous.end() || ds == 0.0) continue;
      const double dbeta = wrap_angle(o.beta - it->second);
      const double dalpha = dbeta + dtheta;
      if (!std::isfinite(dalpha) || std::abs(dalpha) > 0.1) continue;  // a switch of lines
      const double mid = it->second + 0.5 * dbeta;
      tracks[{o.track_id, straight}].push_back({ds, dalpha, std::sin(mid), std::cos(mid)});
      total += dalpha * dalpha;
      ++pairs;
    }
    previous = std::move(now);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (pairs < min_pairs || !(total > 0.0)) return nan;
  auto explained = [&tracks](double yaw) {
    const double sy = std::sin(yaw), cy = std::cos(yaw);
    double g = 0.0;
    for (const auto& [id, v] : tracks) {
      double sxy = 0.0, sxx = 0.0;
      for (const Pair& p : v) {
        const double sx = p.sin_beta * cy + p.cos_beta * sy;  // sin(beta + yaw)
        const double x = p.ds * sx * std::abs(sx);
        sxy += p.dalpha * x;
        sxx += x * x;
      }
      if (sxy > 0.0 && sxx > 0.0) g += sxy * sxy / sxx;
    }
    return g;
  };
  constexpr int kGrid = 720;
  std::array<double, kGrid> g{};
  int best = 0;
  for (int i = 0; i < kGrid; ++i) {
    g[static_cast<std::size_t>(i)] = explained(-kPi + 2.0 * kPi * i / kGrid);
    if (g[static_cast<std::size_t>(i)] > g[static_cast<std::size_t>(best)]) best = i;
  }
  if (g[static_cast<std::size_t>(best)] < min_explained * total) return nan;
  const double gm = g[static_cast<std::size_t>((best + kGrid - 1) % kGrid)];
  const double g0 = g[static_cast<std::size_t>(best)];
  const double gp = g[static_cast<std::size_t>((best + 1) % kGrid)];
  const double curvature = gm - 2.0 * g0 + gp;
  const double offset = curvature < 0.0 ? 0.5 * (gm - gp) / curvature : 0.0;
  return wrap_angle(-kPi + 2.0 * kPi * (best + std::clamp(offset, -0.5, 0.5)) / kGrid);
}

}  // namespace omnivert::calib
