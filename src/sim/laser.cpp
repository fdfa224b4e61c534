#include "omnivert/sim/laser.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "omnivert/core/error.hpp"
#include "omnivert/dataset/laser.hpp"
#include "omnivert/dataset/writer.hpp"

namespace omnivert::sim {

std::string LaserConfig::validate() const {
  if (!(rate_hz > 0)) return "the laser rate must be positive";
  if (rays < 1) return "the laser needs at least one ray";
  if (!(angle_increment != 0) || std::abs(angle_increment) * (rays - 1) > 2 * M_PI + 1e-9)
    return "the laser's rays must span at most a full turn, with a non-zero increment";
  if (!(range_min >= 0) || !(range_max > range_min))
    return "the laser's ranges must satisfy 0 <= range_min < range_max";
  if (!(noise_sigma >= 0)) return "the laser's range noise must not be negative";
  if (!(height > 0)) return "the laser's scan plane must be above the floor";
  return {};
}

std::vector<float> laser_ranges(const World& world,
                                const Pose2& robot,
                                const LaserConfig& c,
                                std::mt19937_64& rng) {
  const double cr = std::cos(robot.z()), sr = std::sin(robot.z());
  const Eigen::Vector2d o(robot.x() + cr * c.x - sr * c.y, robot.y() + sr * c.x + cr * c.y);
  const double yaw = robot.z() + c.yaw;
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<float> out(static_cast<std::size_t>(c.rays));
  for (int k = 0; k < c.rays; ++k) {
    const double a = yaw + c.angle_min + k * c.angle_increment;
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    double best = std::numeric_limits<double>::infinity();
    for (const Wall& w : world.walls) {
      // The scan plane crosses the wall only where the wall spans its height.
      if (w.z0 > c.height || world.top(w) < c.height) continue;
      const Eigen::Vector2d u = w.to - w.from;
      const double den = d.x() * u.y() - d.y() * u.x();  // cross(d, u)
      if (std::abs(den) < 1e-12) continue;
      const Eigen::Vector2d q = w.from - o;
      const double t = (q.x() * u.y() - q.y() * u.x()) / den;  // along the ray
      const double s = (q.x() * d.y() - q.y() * d.x()) / den;  // along the wall, 0..1
      if (t > 0 && s >= 0 && s <= 1 && t < best) best = t;
    }
    double r = best;
    if (std::isfinite(r)) r += c.noise_sigma * noise(rng);
    // Beyond range_max: no return (REP 117: +inf); closer than range_min: too close (-inf).
    if (r > c.range_max) r = std::numeric_limits<double>::infinity();
    if (r < c.range_min) r = -std::numeric_limits<double>::infinity();
    out[static_cast<std::size_t>(k)] = static_cast<float>(r);
  }
  return out;
}

void write_laser(const std::string& dataset_dir,
                 const World& world,
                 const std::vector<MotionPiece>& motion,
                 double t_end,
                 const LaserConfig& c,
                 std::int64_t start_ns,
                 std::mt19937_64& rng) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(dataset_dir) / "laser0";
  fs::create_directories(dir);
  dataset::CsvWriter csv((dir / "data.csv").string(), dataset::kLaserCsvHeader);
  const std::int64_t step_ns = std::llround(1e9 / c.rate_hz);
  for (std::int64_t k = 0;; ++k) {
    const double t = static_cast<double>(k * step_ns) * 1e-9;
    dataset::LaserScan s;
    s.timestamp_ns = start_ns + k * step_ns;
    s.angle_min = c.angle_min;
    s.angle_increment = c.angle_increment;
    s.range_min = c.range_min;
    s.range_max = c.range_max;
    s.ranges = laser_ranges(world, pose_at(motion, t), c, rng);
    csv.row(dataset::laser_csv_row(s));
    if (t >= t_end) break;
  }
  csv.close();
  dataset::LaserSensor sensor{c.x, c.y, c.yaw, c.height};
  std::ofstream y(dir / "sensor.yaml");
  y << dataset::laser_sensor_yaml(
      sensor, "omnivert simulator: 2D laser scanner (dataset format: docs/dataset-format.md)");
  y.close();  // flushed: a full disk shows here
  if (!y)
    throw InputError((dir / "sensor.yaml").string(),
                     0,
                     "cannot write (disk full, or a folder that is not writable?)");
}

}  // namespace omnivert::sim
