#pragma once
// The optional 2D laser scanner of a dataset, laser0/ (docs/dataset-format.md#laser0), and
// the other references a calibration can be checked against by eye (paper Sec. 9.2, Figs. 23
// and 26): the simulator's map of vertical edges (ground_truth/edges.csv) and a user's list of
// known vertical corners (a small CSV in the robot frame of the first image).
//
//   laser0/data.csv     #timestamp [ns],angle_min [rad],angle_increment [rad],range_min [m],
//                       range_max [m],ranges [m]...   (one scan a row, any number of ranges)
//   laser0/sensor.yaml  x, y [m], yaw [rad]: the scanner's pose in the robot frame; z [m]
//
// A range that is not finite (nan, inf, -inf) or lies outside range_min..range_max is no
// return (REP 117 of ROS: inf is "nothing within range", nan an invalid measurement); such
// ranges are counted and skipped. Everything else that is wrong throws InputError naming the
// file, the line and the problem.

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace omnivert::dataset {

// The scanner's pose in the robot frame (x forward, y left, z up).
struct LaserSensor {
  double x = 0, y = 0;  // [m]
  double yaw = 0;       // [rad], the scanner's x-axis from the robot's x-axis
  double z = 0;         // height above the floor [m], for people (not used by the check)
};

struct LaserScan {
  std::int64_t timestamp_ns = 0;
  double angle_min = 0, angle_increment = 0;  // [rad], ray k at angle_min + k angle_increment
  double range_min = 0, range_max = 0;        // [m]
  std::vector<float> ranges;                  // [m]; non-finite: no return
  int line = 0;                               // line in laser0/data.csv
  bool valid(std::size_t k) const {
    const float r = ranges[k];
    return std::isfinite(r) && r >= range_min && r <= range_max;
  }
};

struct LaserData {
  LaserSensor sensor;
  std::vector<LaserScan> scans;
  std::size_t ranges = 0;      // ranges in all
  std::size_t no_returns = 0;  // of those, no return (non-finite or outside the limits)
  std::size_t non_finite = 0;  // of those, nan or inf
  std::string data_csv, sensor_yaml;
  // One line for people: scans, rays, no returns.
  std::string describe() const;
};

// Reads laser0/ of a dataset; nullopt when the folder does not exist. Throws InputError for a
// missing or bad sensor.yaml (the missing field named) or data.csv (file, line, column).
std::optional<LaserData> load_laser(const std::string& dataset_dir);

// laser0/data.csv's header and one row (ranges with %.4f; non-finite as nan, inf, -inf).
inline constexpr const char* kLaserCsvHeader =
    "#timestamp [ns],angle_min [rad],angle_increment [rad],range_min [m],range_max [m],"
    "ranges [m]...";
std::string laser_csv_row(const LaserScan& scan);
// laser0/sensor.yaml; `provenance` is the first comment line.
std::string laser_sensor_yaml(const LaserSensor& sensor, const std::string& provenance);

// A vertical edge of a map: its position [m] and id (ground_truth/edges.csv's line_id, or the
// row's index in a corners file).
struct MapCorner {
  int id = 0;
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
};

// ground_truth/edges.csv of a simulated dataset ("#line_id,x [m],y [m],z_bottom [m],
// z_top [m]", world frame).
std::vector<MapCorner> load_edges_csv(const std::string& path);
// A user's corners file: "#x [m],y [m]", the known vertical corners in the robot frame at the
// first image (x forward, y left). At least one row.
std::vector<MapCorner> load_corners_csv(const std::string& path);

}  // namespace omnivert::dataset
