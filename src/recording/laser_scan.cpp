#include "omnivert/recording/laser_scan.hpp"

#include "omnivert/core/error.hpp"
#include "omnivert/dataset/writer.hpp"
#include "recording/decoder.hpp"

namespace omnivert::recording {

LaserScanMsg decode_laser_scan(std::span<const std::uint8_t> bytes,
                               Serialization s,
                               const std::string& what) {
  Decoder d(bytes, s, what + " (sensor_msgs/LaserScan)");
  LaserScanMsg m;
  m.stamp_ns = d.header();
  m.angle_min = d.get<float>();
  d.get<float>();  // angle_max
  m.angle_increment = d.get<float>();
  d.get<float>();  // time_increment
  d.get<float>();  // scan_time
  m.range_min = d.get<float>();
  m.range_max = d.get<float>();
  m.ranges = d.numbers<float>();
  return m;
}

std::size_t import_laser_scans(Recording& rec,
                               const std::string& topic,
                               const dataset::LaserSensor& pose,
                               const std::filesystem::path& dataset_dir,
                               std::size_t* dropped) {
  const std::filesystem::path dir = dataset_dir / "laser0";
  std::filesystem::create_directories(dir);
  dataset::CsvWriter csv((dir / "data.csv").string(), dataset::kLaserCsvHeader);
  std::size_t n = 0, skipped = 0;
  std::int64_t last = -1;
  rec.read({topic}, [&](const Message& m) {
    const std::string what =
        rec.path() + ", topic " + topic + ", message " + std::to_string(m.index);
    const LaserScanMsg msg = decode_laser_scan(m.data, rec.serialization(), what);
    dataset::LaserScan s;
    s.timestamp_ns = msg.stamp_ns != 0 ? msg.stamp_ns : m.log_time_ns;
    if (s.timestamp_ns <= last) return void(++skipped);
    if (msg.ranges.empty() || msg.angle_increment == 0.0f || !(msg.range_max > msg.range_min))
      throw InputError(what +
                       ": not a usable scan (no ranges, angle_increment 0, or range_max "
                       "not above range_min)");
    last = s.timestamp_ns;
    s.angle_min = msg.angle_min;
    s.angle_increment = msg.angle_increment;
    s.range_min = msg.range_min;
    s.range_max = msg.range_max;
    s.ranges = msg.ranges;
    csv.row(dataset::laser_csv_row(s));
    ++n;
  });
  csv.close();
  if (n == 0) throw InputError(rec.path(), 0, "topic '" + topic + "' has no scans");
  dataset::write_text_file(
      (dir / "sensor.yaml").string(),
      dataset::laser_sensor_yaml(pose, "omnivert import: topic " + topic + " of " + rec.path()));
  if (dropped) *dropped = skipped;
  return n;
}

}  // namespace omnivert::recording
