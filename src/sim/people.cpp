#include "omnivert/sim/people.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "omnivert/core/angles.hpp"

namespace omnivert::sim {

std::vector<Person> draw_people(int count, std::uint64_t seed, const World& world) {
  std::vector<Person> out;
  if (count <= 0 || world.walls.empty()) return out;
  Eigen::Vector2d lo = world.walls.front().from, hi = lo;
  for (const Wall& w : world.walls)
    for (const Eigen::Vector2d& p : {w.from, w.to}) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  lo.array() += 0.5;
  hi.array() -= 0.5;
  std::mt19937_64 rng(seed * 6364136223846793005ULL + 1442695040888963407ULL);
  const auto uniform = [&rng](double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(rng);
  };
  for (int i = 0; i < count; ++i) {
    Person p;
    p.a = {uniform(lo.x(), hi.x()), uniform(lo.y(), hi.y())};
    do {
      p.b = {uniform(lo.x(), hi.x()), uniform(lo.y(), hi.y())};
    } while ((p.b - p.a).norm() < 1.0 && (hi - lo).norm() > 1.5);
    p.speed = uniform(0.8, 1.5);
    p.phase = uniform(0.0, 1.0);
    p.width = uniform(0.38, 0.55);
    p.height = uniform(1.55, 1.9);
    p.grey = uniform(25, 210);
    out.push_back(p);
  }
  return out;
}

Eigen::Vector2d person_position(const Person& p, double t) {
  const double length = (p.b - p.a).norm();
  if (!(length > 0.0)) return p.a;
  const double trip = 2.0 * length;
  double s = std::fmod(p.phase * trip + p.speed * t, trip);
  if (s < 0) s += trip;
  const double f = s < length ? s / length : 2.0 - s / length;  // there, then back
  return p.a + f * (p.b - p.a);
}

namespace {

// A person as the camera sees them: distance, world azimuth and half width [rad], the image
// radii of their feet and head [px].
struct Seen {
  double d, azimuth, half_width, r_bottom, r_top, grey;
  int index;
};

// The people at time t seen from `pose`, far ones first.
std::vector<Seen> seen_people(const std::vector<Person>& people,
                              double t,
                              const CatadioptricCamera& camera,
                              const CameraPose& pose) {
  std::vector<Seen> seen;
  const double el_max = std::asin(camera.xi) - 1e-6;
  for (std::size_t k = 0; k < people.size(); ++k) {
    const Person& p = people[k];
    const Eigen::Vector2d rel = person_position(p, t) - Eigen::Vector2d(pose.x, pose.y);
    const double d = rel.norm();
    if (d < 0.5 * p.width + 0.05) continue;  // walked through the camera: not drawn
    Seen s;
    s.d = d;
    s.azimuth = std::atan2(rel.y(), rel.x());
    s.half_width = std::asin(0.5 * p.width / d);
    // Elevations of the feet and the head from the camera centre; r grows with elevation.
    s.r_bottom = camera.radius_of_elevation(std::atan2(-pose.height, d));
    s.r_top = camera.radius_of_elevation(std::min(el_max, std::atan2(p.height - pose.height, d)));
    s.grey = p.grey;
    s.index = static_cast<int>(k);
    seen.push_back(s);
  }
  std::sort(seen.begin(), seen.end(), [](const Seen& a, const Seen& b) { return a.d > b.d; });
  return seen;
}

}  // namespace

void hide_lines(const std::vector<Person>& people,
                double t,
                const CatadioptricCamera& camera,
                const CameraPose& pose,
                double min_line_px,
                std::vector<VisibleLine>& lines) {
  const std::vector<Seen> seen = seen_people(people, t, camera, pose);
  if (seen.empty()) return;
  std::vector<VisibleLine> kept;
  for (VisibleLine l : lines) {
    const double azimuth = pose.yaw + l.bearing;
    bool gone = false;
    for (const Seen& s : seen) {
      if (!(s.d < l.distance) || std::abs(angle_diff(azimuth, s.azimuth)) > s.half_width) continue;
      // What the person leaves of [r_inner, r_outer]: the longer piece beside [r_bottom, r_top].
      const double below = std::min(l.r_outer, s.r_bottom) - l.r_inner;
      const double above = l.r_outer - std::max(l.r_inner, s.r_top);
      if (below <= 0.0 && above <= 0.0) {
        if (l.r_outer > s.r_bottom && l.r_inner < s.r_top) gone = true;
        continue;
      }
      if (below >= above)
        l.r_outer = std::min(l.r_outer, s.r_bottom);
      else
        l.r_inner = std::max(l.r_inner, s.r_top);
    }
    if (!gone && l.r_outer - l.r_inner >= min_line_px) kept.push_back(l);
  }
  lines = std::move(kept);
}

std::vector<std::pair<int, double>> occluder_edges(const std::vector<Person>& people,
                                                   double t,
                                                   const CatadioptricCamera& camera,
                                                   const CameraPose& pose) {
  std::vector<std::pair<int, double>> edges;
  for (const Seen& s : seen_people(people, t, camera, pose)) {
    // As hide_lines: a world azimuth a is seen at the camera bearing a - yaw.
    edges.emplace_back(s.index, wrap_angle(s.azimuth - s.half_width - pose.yaw));
    edges.emplace_back(s.index, wrap_angle(s.azimuth + s.half_width - pose.yaw));
  }
  return edges;
}

void paint_people(const std::vector<Person>& people,
                  double t,
                  const CatadioptricCamera& camera,
                  const CameraPose& pose,
                  cv::Mat1f& image) {
  const std::vector<Seen> seen = seen_people(people, t, camera, pose);
  if (seen.empty()) return;
  const double r_rim = camera.rim_radius(), r_out = r_rim + 1.0;
  const int v0 = std::max(0, static_cast<int>(camera.cy - r_out)),
            v1 = std::min(image.rows - 1, static_cast<int>(camera.cy + r_out) + 1);
  const int u0 = std::max(0, static_cast<int>(camera.cx - r_out)),
            u1 = std::min(image.cols - 1, static_cast<int>(camera.cx + r_out) + 1);
  for (int v = v0; v <= v1; ++v) {
    float* row = image[v];
    for (int u = u0; u <= u1; ++u) {
      const double dx = u - camera.cx, dy = v - camera.cy, r = std::hypot(dx, dy);
      if (r < 1.0) continue;
      // The pixel's world azimuth: camera yaw plus its bearing (a = bearing_sign * beta).
      const double azimuth = pose.yaw + camera.bearing_sign * std::atan2(dy, dx);
      for (const Seen& s : seen) {
        // Coverage of the pixel's footprint, 1 px tangentially (1 / r rad) and 1 px radially.
        const double across = s.half_width - std::abs(angle_diff(azimuth, s.azimuth));
        const double c_t = std::clamp(across * r + 0.5, 0.0, 1.0);
        if (c_t <= 0.0) continue;
        // Between feet and head, and inside the mirror's rim (beyond it the rim is drawn).
        const double inside = std::min({s.r_top - r, r - s.r_bottom, r_rim - r});
        const double c_r = std::clamp(inside + 0.5, 0.0, 1.0);
        const double c = c_t * c_r;
        if (c <= 0.0) continue;
        // A cylinder's shading: darker towards its sides.
        const double x = std::clamp(1.0 - across / s.half_width, 0.0, 1.0);
        const double grey = s.grey * (1.0 - 0.25 * x * x);
        row[u] = static_cast<float>((1.0 - c) * row[u] + c * grey);
      }
    }
  }
}

}  // namespace omnivert::sim
