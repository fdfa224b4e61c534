#pragma once
// sensor_msgs/LaserScan from a recording into laser0/ of the dataset (dataset/laser.hpp):
// `omnivert import --laser-topic TOPIC --laser-pose X Y YAW` (docs/import.md#laser-scans).

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "omnivert/dataset/laser.hpp"
#include "omnivert/recording/recording.hpp"

namespace omnivert::recording {

// sensor_msgs/LaserScan (angle_max, time_increment, scan_time and intensities are not kept).
struct LaserScanMsg {
  std::int64_t stamp_ns = 0;
  float angle_min = 0, angle_increment = 0, range_min = 0, range_max = 0;
  std::vector<float> ranges;
};

// Decodes ROS 1 serialisation or CDR; throws InputError naming `what` when the bytes do not
// hold the message.
LaserScanMsg decode_laser_scan(std::span<const std::uint8_t> bytes,
                               Serialization s,
                               const std::string& what);

// Reads every message of `topic` (type sensor_msgs/LaserScan) and writes laser0/data.csv and
// laser0/sensor.yaml (the scanner's pose on the robot, `pose`, which the message does not hold)
// under `dataset_dir`. Scans whose stamp does not advance are dropped (counted in
// `*dropped`). Returns the number of scans written; throws InputError when the topic has no
// scan.
std::size_t import_laser_scans(Recording& rec,
                               const std::string& topic,
                               const dataset::LaserSensor& pose,
                               const std::filesystem::path& dataset_dir,
                               std::size_t* dropped = nullptr);

}  // namespace omnivert::recording
