#include "omnivert/recording/laser_scan.hpp"

#include "omnivert/core/error.hpp"
#include "omnivert/dataset/writer.hpp"
#include "recording/bytes.hpp"

namespace omnivert::recording {

namespace {

// ROS 1: packed little endian, sequences <u32 length><items>, time <u32 s><u32 ns>, a header
// with a sequence number. CDR (XCDR1): a 4-byte encapsulation header, primitives aligned to
// their size from its end, strings with their NUL, time <i32 s><u32 ns>.
class ScanReader {
 public:
  ScanReader(std::span<const std::uint8_t> bytes, Serialization s, const std::string& what)
      : r_(bytes, what), cdr_(s == Serialization::kCdr) {
    if (cdr_ && r_.bytes(4)[1] != 0x01) r_.fail("CDR encapsulation is not little-endian plain CDR");
  }
  template <typename T>
  T get() {
    if (cdr_) {
      const std::size_t off = r_.pos() - 4;
      if (off % sizeof(T)) r_.bytes(sizeof(T) - off % sizeof(T));
    }
    return r_.get<T>();
  }
  std::int64_t header() {
    if (!cdr_) get<std::uint32_t>();  // seq
    const auto sec = get<std::int32_t>();
    const auto nsec = get<std::uint32_t>();
    r_.bytes(get<std::uint32_t>());  // frame_id
    return static_cast<std::int64_t>(cdr_ ? sec : static_cast<std::uint32_t>(sec)) * 1'000'000'000 +
           nsec;
  }
  std::vector<float> floats() {
    const auto n = get<std::uint32_t>();
    r_.need(static_cast<std::size_t>(n) * 4);
    std::vector<float> v(n);
    for (auto& x : v) x = get<float>();
    return v;
  }

 private:
  ByteReader r_;
  bool cdr_;
};

}  // namespace

LaserScanMsg decode_laser_scan(std::span<const std::uint8_t> bytes,
                               Serialization s,
                               const std::string& what) {
  ScanReader d(bytes, s, what + " (sensor_msgs/LaserScan)");
  LaserScanMsg m;
  m.stamp_ns = d.header();
  m.angle_min = d.get<float>();
  d.get<float>();  // angle_max
  m.angle_increment = d.get<float>();
  d.get<float>();  // time_increment
  d.get<float>();  // scan_time
  m.range_min = d.get<float>();
  m.range_max = d.get<float>();
  m.ranges = d.floats();
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
