#include "calib/warm_start.hpp"

#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <vector>

#include "calib/batch_problem.hpp"

namespace omnivert::calib::internal {

namespace {

// The rigid motion of the plane that takes pose `from` to pose `to` (x, y, theta).
struct Rigid {
  Eigen::Vector3d from, to;
  Eigen::Vector2d point(const Eigen::Vector2d& p) const {
    const double c = std::cos(to(2) - from(2)), s = std::sin(to(2) - from(2));
    const Eigen::Vector2d d = p - from.head<2>();
    return to.head<2>() + Eigen::Vector2d(c * d(0) - s * d(1), s * d(0) + c * d(1));
  }
  Eigen::Vector3d pose(const Eigen::Vector3d& q) const {
    const Eigen::Vector2d p = point(q.head<2>());
    return {p(0), p(1), q(2) + to(2) - from(2)};
  }
};

}  // namespace

BatchPoint warm_start(const CalibrationRun& run,
                      const CalibrationOptions& options,
                      const BatchPoint& start) {
  const int n = static_cast<int>(run.frames.size());
  const int window = options.refinement.warm_start_window;
  const int overlap = options.refinement.warm_start_overlap;
  if (window <= 0 || n < 2 * window || static_cast<int>(start.poses.size()) != n) return start;
  const auto t0 = std::chrono::steady_clock::now();
  // Each feature sits where the filter put it from the pose of its last frame.
  std::map<int, int> last;
  for (int k = 0; k < n; ++k)
    for (const BearingObservation& o : run.frames[static_cast<std::size_t>(k)].observations)
      last[o.track_id] = k;
  CalibrationOptions o = options;
  o.noise.track_bias_sigma = 0.0;  // the windows hold no biases
  BatchPoint at = start;
  const ceres::Solver::Options so = small_solver_options();
  std::size_t total = 1;  // windows start at 0, window - overlap, ... until one reaches n
  for (int a = 0; a + window < n; a += window - overlap) ++total;
  int windows = 0, iterations = 0;
  for (int a = 0;;) {
    const int b = std::min(n, a + window);
    CalibrationRun sub;  // no clock: the time offset stays as it is
    sub.frames.assign(run.frames.begin() + a, run.frames.begin() + b);
    BatchPoint p;
    p.poses.assign(at.poses.begin() + a, at.poses.begin() + b);
    p.features = at.features;
    p.extrinsics = at.extrinsics;
    Built w = build(sub, o, p, true);  // the window's first pose is its gauge
    w.problem->SetParameterBlockConstant(w.ex.data());
    ceres::Solver::Summary summary;
    ceres::Solve(so, w.problem.get(), &summary);
    ++windows;
    iterations += static_cast<int>(summary.iterations.size());
    if (options.progress)
      options.progress("refinement: warm start", static_cast<std::size_t>(windows), total);
    const BatchPoint solved = point_of(w);
    // The rigid motion of each pose of the window, for the features not solved in it whose
    // last frame lies in it or after it, and of the window's last pose for the poses after it.
    std::vector<Rigid> moved;
    for (int k = a; k < b; ++k)
      moved.push_back(
          {at.poses[static_cast<std::size_t>(k)], solved.poses[static_cast<std::size_t>(k - a)]});
    for (auto& [id, f] : at.features) {
      if (const auto s = solved.features.find(id); s != solved.features.end()) {
        f = s->second;
        continue;
      }
      const auto l = last.find(id);
      if (l == last.end() || l->second <= a) continue;
      f = moved[static_cast<std::size_t>(std::min(l->second, b - 1) - a)].point(f);
    }
    for (int k = a + 1; k < b; ++k)
      at.poses[static_cast<std::size_t>(k)] = solved.poses[static_cast<std::size_t>(k - a)];
    for (int k = b; k < n; ++k)
      at.poses[static_cast<std::size_t>(k)] =
          moved.back().pose(at.poses[static_cast<std::size_t>(k)]);
    if (b == n) break;
    a = b - overlap;
  }
  spdlog::debug("refinement warm start: {} windows of {} frames, {} iterations, {:.2f} s",
                windows,
                window,
                iterations,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return at;
}

}  // namespace omnivert::calib::internal
