#include "omnivert/sim/trajectory.hpp"

#include <cmath>
#include <filesystem>

#include <yaml-cpp/yaml.h>

#include "core/yaml_fields.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::sim {

namespace {

Pose2 advance(const Pose2& p, double v, double omega, double dt) {
  // Exact integration of the unicycle with constant (v, omega).
  const double th = p.z();
  const double dth = omega * dt;
  if (std::abs(dth) < 1e-9) {
    return {p.x() + v * dt * std::cos(th + 0.5 * dth),
            p.y() + v * dt * std::sin(th + 0.5 * dth),
            th + dth};
  }
  const double r = v / omega;
  return {p.x() + r * (std::sin(th + dth) - std::sin(th)),
          p.y() - r * (std::cos(th + dth) - std::cos(th)),
          th + dth};
}

Segment straight(double d) {
  Segment s;
  s.kind = Segment::Kind::kStraight;
  s.distance = d;
  return s;
}
Segment turn(double deg) {
  Segment s;
  s.kind = Segment::Kind::kTurn;
  s.angle = deg2rad(deg);
  return s;
}

}  // namespace

std::vector<MotionPiece> Trajectory::pieces(const Pose2& start_pose) const {
  std::vector<MotionPiece> out;
  Pose2 p = start_pose;
  double t = 0.0;
  for (const Segment& s : segments) {
    MotionPiece m;
    m.t0 = t;
    m.start = p;
    double dt = 0.0;
    switch (s.kind) {
      case Segment::Kind::kStraight:
        dt = std::abs(s.distance) / speed;
        m.v = std::copysign(speed, s.distance);
        break;
      case Segment::Kind::kTurn:
        dt = std::abs(s.angle) / turn_rate;
        m.omega = std::copysign(turn_rate, s.angle);
        break;
      case Segment::Kind::kArc:
        dt = std::abs(s.distance) / speed;
        m.v = std::copysign(speed, s.distance);
        m.omega = s.angle / dt;
        break;
      case Segment::Kind::kWait:
        dt = s.duration;
        break;
    }
    if (dt <= 0.0) continue;
    m.t1 = t + dt;
    out.push_back(m);
    p = advance(p, m.v, m.omega, dt);
    t = m.t1;
  }
  return out;
}

std::string Trajectory::validate() const {
  if (!(speed > 0.0)) return "speed must be positive";
  if (!(turn_rate > 0.0)) return "turn_rate must be positive";
  if (segments.empty()) return "a trajectory needs at least one segment";
  return {};
}

double duration(const std::vector<MotionPiece>& motion) {
  return motion.empty() ? 0.0 : motion.back().t1;
}

Pose2 pose_at(const std::vector<MotionPiece>& motion, double t) {
  if (motion.empty()) return Pose2::Zero();
  if (t <= motion.front().t0) return motion.front().start;
  for (const MotionPiece& m : motion) {
    if (t <= m.t1) return advance(m.start, m.v, m.omega, t - m.t0);
  }
  const MotionPiece& m = motion.back();
  return advance(m.start, m.v, m.omega, m.t1 - m.t0);
}

Eigen::Vector2d velocity_at(const std::vector<MotionPiece>& motion, double t) {
  for (const MotionPiece& m : motion) {
    if (t >= m.t0 && t < m.t1) return {m.v, m.omega};
  }
  return Eigen::Vector2d::Zero();
}

std::vector<std::string> trajectory_presets() { return {"paper", "zigzag", "straight", "tour"}; }

namespace {

Trajectory preset(const std::string& name) {
  Trajectory t;
  t.name = name;
  if (name == "paper") {
    // Sec. 9.2: about 2.3 m straight, then a 180 degree rotation about the wheel centre;
    // about 3.8 cm between frames at 3 Hz.
    t.speed = 0.114;
    t.turn_rate = 0.3;
    t.segments = {straight(2.3), turn(180)};
  } else if (name == "zigzag") {
    t.speed = 0.114;
    t.turn_rate = 0.3;
    for (int i = 0; i < 3; ++i) {
      t.segments.push_back(straight(0.8));
      t.segments.push_back(turn(45));
      t.segments.push_back(straight(0.5));
      t.segments.push_back(turn(-90));
      t.segments.push_back(straight(0.5));
      t.segments.push_back(turn(45));
    }
    t.segments.push_back(turn(180));
  } else if (name == "straight") {
    t.speed = 0.114;
    t.segments = {straight(4.0)};
  } else if (name == "tour") {
    // 5 cm per frame at 3 Hz; 9 laps of a 4 m x 1 m loop (about 92 m with the turns).
    t.speed = 0.15;
    t.turn_rate = 0.3;
    for (int lap = 0; lap < 9; ++lap) {
      for (double d : {4.0, 1.0, 4.0, 1.0}) {
        t.segments.push_back(straight(d));
        t.segments.push_back(turn(90));
      }
    }
  } else {
    throw InputError("unknown trajectory '" + name +
                     "' (presets: paper, zigzag, straight, tour; or a YAML file)");
  }
  return t;
}

Trajectory parse(const std::string& file) {
  const YAML::Node root = yaml::load_file(file);
  Trajectory t;
  t.name = yaml::optional_string(root, "name", file)
               .value_or(std::filesystem::path(file).stem().string());
  t.speed = yaml::optional_number(root, "speed", file, true).value_or(t.speed);
  t.turn_rate = yaml::optional_number(root, "turn_rate", file, true).value_or(t.turn_rate);
  if (!(t.speed > 0))
    throw InputError(file, yaml::line_of(root["speed"]), "field 'speed' must be positive");
  if (!(t.turn_rate > 0)) {
    throw InputError(file, yaml::line_of(root["turn_rate"]), "field 'turn_rate' must be positive");
  }
  if (const auto st = yaml::optional_numbers(root, "start", 3, file)) {
    t.has_start = true;
    t.start = {(*st)[0], (*st)[1], (*st)[2]};
  }
  const YAML::Node segs = root["segments"];
  if (!segs) throw InputError(file, 0, "missing required field 'segments' (a list)");
  if (!segs.IsSequence())
    throw InputError(file, yaml::line_of(segs), "field 'segments' must be a list");
  int repeat = 1;
  if (const auto r = yaml::optional_number(root, "repeat", file, true)) {
    if (*r < 1 || *r != std::floor(*r)) {
      throw InputError(
          file, yaml::line_of(root["repeat"]), "field 'repeat' must be a whole number >= 1");
    }
    repeat = static_cast<int>(*r);
  }
  std::vector<Segment> one;
  for (const YAML::Node& n : segs) {
    const int line = yaml::line_of(n);
    if (!n.IsMap() || n.size() != 1) {
      throw InputError(file,
                       line,
                       "each segment must be one of: straight: M, turn_deg: D, "
                       "arc: {length: M, angle_deg: D}, wait: S");
    }
    Segment s;
    if (n["straight"]) {
      s.kind = Segment::Kind::kStraight;
      s.distance = yaml::required_number(n, "straight", file);
    } else if (n["turn_deg"]) {
      s.kind = Segment::Kind::kTurn;
      s.angle = deg2rad(yaml::required_number(n, "turn_deg", file));
    } else if (n["arc"]) {
      const YAML::Node a = n["arc"];
      if (!a.IsMap()) throw InputError(file, line, "arc must be {length: M, angle_deg: D}");
      s.kind = Segment::Kind::kArc;
      s.distance = yaml::required_number(a, "length", file);
      s.angle = deg2rad(yaml::required_number(a, "angle_deg", file));
    } else if (n["wait"]) {
      s.kind = Segment::Kind::kWait;
      s.duration = yaml::required_number(n, "wait", file, true);
    } else {
      throw InputError(file,
                       line,
                       "unknown segment '" + n.begin()->first.as<std::string>() +
                           "' (expected straight, turn_deg, arc or wait)");
    }
    one.push_back(s);
  }
  for (int i = 0; i < repeat; ++i) t.segments.insert(t.segments.end(), one.begin(), one.end());
  const std::string problem = t.validate();
  if (!problem.empty()) throw InputError(file, 0, problem);
  return t;
}

}  // namespace

Trajectory load_trajectory(const std::string& name_or_file) {
  for (const auto& p : trajectory_presets()) {
    if (p == name_or_file) return preset(p);
  }
  std::error_code ec;
  if (!std::filesystem::exists(name_or_file, ec)) {
    throw InputError(name_or_file,
                     0,
                     "no such trajectory file, and not a preset (paper, zigzag, straight, tour)");
  }
  return parse(name_or_file);
}

}  // namespace omnivert::sim
