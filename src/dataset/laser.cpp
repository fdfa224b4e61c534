#include "omnivert/dataset/laser.hpp"

#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <yaml-cpp/yaml.h>

#include "core/yaml_fields.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::dataset {

namespace fs = std::filesystem;

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& t) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = t.find(',', start);
    out.push_back(
        trim(t.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

// A number; with `allow_non_finite`, also nan, inf and -inf (a range without a return).
double number(const std::string& s,
              const std::string& column,
              const std::string& path,
              int line,
              bool allow_non_finite = false) {
  double v = 0;
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  if (s.empty() || r.ec != std::errc() || r.ptr != end || (!allow_non_finite && !std::isfinite(v)))
    throw InputError(path,
                     line,
                     "cannot parse " + column + " '" + s + "' as a " +
                         (allow_non_finite ? "number (or nan, inf)" : "finite number"));
  return v;
}

std::int64_t timestamp(const std::string& s, const std::string& path, int line) {
  std::int64_t v = 0;
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  if (s.empty() || r.ec != std::errc() || r.ptr != end || v < 0)
    throw InputError(
        path, line, "cannot parse timestamp '" + s + "' (expected a non-negative integer in ns)");
  return v;
}

// Calls row(fields, line) for every data row of a '#'-headed CSV file.
template <typename Row>
void for_each_row(const std::string& path, const std::string& what, Row row) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path, 0, "file not found");
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "cannot be opened for reading");
  std::string text;
  int line = 0;
  bool header = false;
  while (std::getline(in, text)) {
    ++line;
    const std::string t = trim(text);
    if (t.empty()) continue;
    if (!header) {
      if (t[0] != '#')
        throw InputError(path, line, "expected a header line starting with '#' (" + what + ")");
      header = true;
      continue;
    }
    if (t[0] == '#') throw InputError(path, line, "unexpected second header line");
    row(split(t), line);
  }
  if (!header)
    throw InputError(path, 0, "file is empty (expected a '#' header line: " + what + ")");
}

LaserSensor load_sensor(const std::string& path) {
  const YAML::Node root = yaml::load_file(path);
  LaserSensor s;
  s.x = yaml::required_number(root, "x", path);
  s.y = yaml::required_number(root, "y", path);
  s.yaw = yaml::required_number(root, "yaw", path);
  s.z = yaml::optional_number(root, "z", path).value_or(0.0);
  return s;
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

}  // namespace

std::optional<LaserData> load_laser(const std::string& dataset_dir) {
  const fs::path dir = fs::path(dataset_dir) / "laser0";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return std::nullopt;
  LaserData d;
  d.sensor_yaml = (dir / "sensor.yaml").string();
  d.data_csv = (dir / "data.csv").string();
  d.sensor = load_sensor(d.sensor_yaml);
  const std::string& path = d.data_csv;
  for_each_row(
      path,
      "timestamp, angle_min, angle_increment, range_min, range_max, ranges",
      [&](const std::vector<std::string>& f, int line) {
        if (f.size() < 6)
          throw InputError(path,
                           line,
                           "expected at least 6 comma-separated columns (timestamp, angle_min, "
                           "angle_increment, range_min, range_max and one range or more), got " +
                               std::to_string(f.size()));
        LaserScan s;
        s.line = line;
        s.timestamp_ns = timestamp(f[0], path, line);
        if (!d.scans.empty() && s.timestamp_ns <= d.scans.back().timestamp_ns)
          throw InputError(path,
                           line,
                           "timestamp " + std::to_string(s.timestamp_ns) + " is not later than " +
                               std::to_string(d.scans.back().timestamp_ns) + " on line " +
                               std::to_string(d.scans.back().line) + ": timestamps must increase");
        s.angle_min = number(f[1], "angle_min", path, line);
        s.angle_increment = number(f[2], "angle_increment", path, line);
        s.range_min = number(f[3], "range_min", path, line);
        s.range_max = number(f[4], "range_max", path, line);
        if (s.angle_increment == 0.0)
          throw InputError(path, line, "angle_increment is 0: the rays' directions are unknown");
        if (std::abs(s.angle_increment) * static_cast<double>(f.size() - 6) > 2.0 * M_PI + 1e-6)
          throw InputError(path,
                           line,
                           std::to_string(f.size() - 5) + " rays of " +
                               fmt("%g", s.angle_increment) + " rad span more than a full turn");
        if (!(s.range_min >= 0) || !(s.range_max > s.range_min))
          throw InputError(path,
                           line,
                           "range_min " + f[3] + ", range_max " + f[4] +
                               ": expected 0 <= range_min < range_max");
        s.ranges.reserve(f.size() - 5);
        for (std::size_t k = 5; k < f.size(); ++k) {
          const double r =
              number(f[k],
                     "range " + std::to_string(k - 5) + " (column " + std::to_string(k + 1) + ")",
                     path,
                     line,
                     true);
          s.ranges.push_back(static_cast<float>(r));
          d.non_finite += std::isfinite(r) ? 0 : 1;
          d.no_returns += s.valid(s.ranges.size() - 1) ? 0 : 1;
        }
        d.ranges += s.ranges.size();
        d.scans.push_back(std::move(s));
      });
  if (d.scans.empty()) throw InputError(path, 0, "no scans (only the header)");
  if (d.no_returns == d.ranges)
    throw InputError(path,
                     0,
                     "no scan has a usable range: all " + std::to_string(d.ranges) +
                         " ranges are nan, inf or outside range_min..range_max");
  return d;
}

std::string LaserData::describe() const {
  char buf[300];
  std::snprintf(buf,
                sizeof buf,
                "%zu scans, %zu ranges, %zu of them no return (%zu not finite, the others "
                "outside range_min..range_max)",
                scans.size(),
                ranges,
                no_returns,
                non_finite);
  return buf;
}

std::string laser_csv_row(const LaserScan& s) {
  std::string row = std::to_string(s.timestamp_ns) + "," + fmt("%.9g", s.angle_min) + "," +
                    fmt("%.9g", s.angle_increment) + "," + fmt("%.6g", s.range_min) + "," +
                    fmt("%.6g", s.range_max);
  for (const float r : s.ranges) {
    row += ',';
    if (std::isnan(r))
      row += "nan";
    else if (std::isinf(r))
      row += r > 0 ? "inf" : "-inf";
    else
      row += fmt("%.4f", r);
  }
  return row;
}

std::string laser_sensor_yaml(const LaserSensor& s, const std::string& provenance) {
  std::string y = "# " + provenance + "\n";
  y += "# the scanner's pose in the robot frame (x forward, y left, z up)\n";
  y += "x: " + fmt("%.9g", s.x) + "     # [m]\n";
  y += "y: " + fmt("%.9g", s.y) + "     # [m]\n";
  y += "yaw: " + fmt("%.9g", s.yaw) + "   # [rad]\n";
  y += "z: " + fmt("%.9g", s.z) + "     # [m], height of the scan plane\n";
  return y;
}

std::vector<MapCorner> load_edges_csv(const std::string& path) {
  std::vector<MapCorner> out;
  for_each_row(path,
               "line_id, x [m], y [m], z_bottom [m], z_top [m]",
               [&](const std::vector<std::string>& f, int line) {
                 if (f.size() < 3)
                   throw InputError(path, line, "expected at least 3 columns (line_id, x, y)");
                 MapCorner c;
                 c.id = static_cast<int>(number(f[0], "line_id", path, line));
                 c.p = {number(f[1], "x", path, line), number(f[2], "y", path, line)};
                 out.push_back(c);
               });
  return out;
}

std::vector<MapCorner> load_corners_csv(const std::string& path) {
  std::vector<MapCorner> out;
  for_each_row(path, "x [m], y [m]", [&](const std::vector<std::string>& f, int line) {
    if (f.size() < 2) throw InputError(path, line, "expected 2 columns (x [m], y [m])");
    MapCorner c;
    c.id = static_cast<int>(out.size());
    c.p = {number(f[0], "x", path, line), number(f[1], "y", path, line)};
    out.push_back(c);
  });
  if (out.empty()) throw InputError(path, 0, "no corners (only the header)");
  return out;
}

}  // namespace omnivert::dataset
