#include "omnivert/dataset/poses_to_wheels.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::dataset {

namespace {

std::string where(const PosesToWheelsOptions& o, std::size_t i, std::int64_t t_ns) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "pose %zu (t = %.9f s)", i, static_cast<double>(t_ns) * 1e-9);
  return (o.source.empty() ? std::string() : o.source + ", ") + buf;
}

bool is_zero_pose(const PoseRecord& p) {
  return std::abs(p.x) < 1e-9 && std::abs(p.y) < 1e-9 && std::abs(p.theta) < 1e-9;
}

}  // namespace

double yaw_of_quaternion(double qx, double qy, double qz, double qw) {
  return std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz));
}

std::vector<WheelRecord> wheel_travel_from_poses(std::span<const PoseRecord> poses,
                                                 const PosesToWheelsOptions& o) {
  if (!(o.wheel_base > 0))
    throw InputError("the wheel base must be positive to turn poses into wheel travel");
  std::vector<WheelRecord> out;
  out.reserve(poses.size());
  WheelTravel travel;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const PoseRecord& p = poses[i];
    if (i > 0) {
      const PoseRecord& q = poses[i - 1];
      if (p.timestamp_ns <= q.timestamp_ns) {
        throw InputError(where(o, i, p.timestamp_ns) + ": the time does not increase (previous " +
                         std::to_string(q.timestamp_ns) + " ns)");
      }
      const double dx = p.x - q.x, dy = p.y - q.y;
      const double chord_len = std::hypot(dx, dy);
      const double dt = static_cast<double>(p.timestamp_ns - q.timestamp_ns) * 1e-9;
      if (is_zero_pose(p) && !is_zero_pose(q) && (chord_len > 1e-3 || std::abs(q.theta) > 1e-3)) {
        throw InputError(where(o, i, p.timestamp_ns) +
                         ": odometry reset (the pose jumps back to zero from x = " +
                         std::to_string(q.x) + ", y = " + std::to_string(q.y) +
                         "); import the part before or after the reset separately");
      }
      if (chord_len > o.max_speed * dt) {
        throw InputError(where(o, i, p.timestamp_ns) + ": the pose jumps by " +
                         std::to_string(chord_len) + " m in " + std::to_string(dt) +
                         " s, faster than " + std::to_string(o.max_speed) + " m/s");
      }
      // Eq. (14): the step runs along theta + dtheta/2; its length there is the chord.
      const double dtheta = wrap_angle(p.theta - q.theta);
      const double mid = q.theta + 0.5 * dtheta;
      const double chord = dx * std::cos(mid) + dy * std::sin(mid);
      // The arc through the chord: s = chord * (dtheta/2) / sin(dtheta/2).
      const double h = 0.5 * dtheta;
      const double arc = std::abs(h) < 1e-9 ? chord : chord * h / std::sin(h);
      // Eq. (15) inverted: rho_R - rho_L = e dtheta, (rho_R + rho_L) / 2 = s.
      travel.right += arc + 0.5 * o.wheel_base * dtheta;
      travel.left += arc - 0.5 * o.wheel_base * dtheta;
    }
    out.push_back({p.timestamp_ns, travel, static_cast<int>(i) + 1});
  }
  return out;
}

std::vector<PoseRecord> read_tum_poses(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "cannot be opened for reading");
  std::vector<PoseRecord> poses;
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    for (char& c : text)
      if (c == ',' || c == '\t' || c == '\r') c = ' ';
    const auto first = text.find_first_not_of(' ');
    if (first == std::string::npos || text[first] == '#') continue;
    std::istringstream s(text);
    double v[8];
    for (double& x : v) {
      if (!(s >> x)) {
        throw InputError(path, line, "expected 't x y z qx qy qz qw' (8 numbers, t in seconds)");
      }
    }
    PoseRecord p;
    p.timestamp_ns = std::llround(v[0] * 1e9);
    p.x = v[1];
    p.y = v[2];
    p.theta = yaw_of_quaternion(v[4], v[5], v[6], v[7]);
    poses.push_back(p);
  }
  if (poses.empty()) throw InputError(path, 0, "no poses");
  return poses;
}

}  // namespace omnivert::dataset
