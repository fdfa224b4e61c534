#include "omnivert/dataset/dataset.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <unordered_map>

#include <yaml-cpp/yaml.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/yaml_fields.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/core/file_io.hpp"
#include "omnivert/image/grey.hpp"

namespace omnivert::dataset {

namespace fs = std::filesystem;

namespace {

struct CsvRow {
  int line = 0;
  std::vector<std::string> fields;
};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

// Reads a CSV file whose first line is a '#' header with at least `columns` columns; returns
// the header and the data rows (blank lines skipped), each cut to `columns` fields: columns
// beyond those are another tool's, ignored as EuRoC-style readers do, and the rows that had
// any are counted in a note appended to `notes`. `what` names the columns for messages.
// Each row is handed to `visit` as it is read (a long run's lines.csv holds millions of rows:
// kept as strings they took several times the memory of the records made from them).
template <typename Visit>
void for_each_csv_row(const std::string& path,
                      std::size_t columns,
                      const std::string& what,
                      std::string* header_out,
                      std::vector<std::string>* notes,
                      Visit&& visit) {
  int extra_rows = 0;
  if (const std::string why = unreadable_file_reason(path); !why.empty()) {
    throw InputError(path, 0, why);
  }
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "cannot be opened for reading");
  std::string text;
  int line = 0;
  bool header_seen = false;
  while (std::getline(in, text)) {
    ++line;
    const std::string t = trim(text);
    if (t.empty()) continue;
    if (!header_seen) {
      if (t[0] != '#') {
        throw InputError(path, line, "expected a header line starting with '#' (" + what + ")");
      }
      header_seen = true;
      if (header_out) *header_out = t;
      continue;
    }
    if (t[0] == '#') throw InputError(path, line, "unexpected second header line");
    CsvRow row;
    row.line = line;
    std::size_t start = 0;
    while (true) {
      const auto comma = t.find(',', start);
      row.fields.push_back(
          trim(t.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (row.fields.size() > columns) {
      row.fields.resize(columns);
      ++extra_rows;
    }
    if (row.fields.size() != columns) {
      throw InputError(path,
                       line,
                       "expected " + std::to_string(columns) + " comma-separated columns (" + what +
                           "), got " + std::to_string(row.fields.size()));
    }
    visit(row);
  }
  if (!header_seen)
    throw InputError(path, 0, "file is empty (expected a '#' header line: " + what + ")");
  if (extra_rows > 0 && notes)
    notes->push_back(path + ": " + std::to_string(extra_rows) + " rows have columns beyond the " +
                     std::to_string(columns) + " read; those were ignored");
}

// All the rows of for_each_csv_row at once.
std::vector<CsvRow> read_csv(const std::string& path,
                             std::size_t columns,
                             const std::string& what,
                             std::string* header_out,
                             std::vector<std::string>* notes) {
  std::vector<CsvRow> rows;
  for_each_csv_row(
      path, columns, what, header_out, notes, [&](CsvRow& r) { rows.push_back(std::move(r)); });
  return rows;
}

std::int64_t parse_timestamp(const std::string& s, const std::string& path, int line) {
  std::int64_t v = 0;
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  if (s.empty() || r.ec != std::errc() || r.ptr != end || v < 0) {
    throw InputError(
        path, line, "cannot parse timestamp '" + s + "' (expected a non-negative integer in ns)");
  }
  return v;
}

double parse_double(const std::string& s,
                    const std::string& column,
                    const std::string& path,
                    int line) {
  double v = 0;
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  if (s.empty() || r.ec != std::errc() || r.ptr != end || !std::isfinite(v)) {
    throw InputError(path, line, "cannot parse " + column + " '" + s + "' as a finite number");
  }
  return v;
}

int parse_int(const std::string& s, const std::string& column, const std::string& path, int line) {
  int v = 0;
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  if (s.empty() || r.ec != std::errc() || r.ptr != end) {
    throw InputError(path, line, "cannot parse " + column + " '" + s + "' as an integer");
  }
  return v;
}

// Timestamps must strictly increase.
void check_increasing(
    std::int64_t prev, int prev_line, std::int64_t t, const std::string& path, int line) {
  if (t == prev) {
    throw InputError(path,
                     line,
                     "duplicate timestamp " + std::to_string(t) + " (also on line " +
                         std::to_string(prev_line) + ")");
  }
  if (t < prev) {
    throw InputError(path,
                     line,
                     "timestamp " + std::to_string(t) + " is earlier than " + std::to_string(prev) +
                         " on line " + std::to_string(prev_line) + ": timestamps must increase");
  }
}

std::string rel(const std::string& root, const std::string& sub) {
  return (fs::path(root) / sub).string();
}

cv::Mat1b read_checked_image(const std::string& path, const CameraGeometry& cam) {
  cv::Mat raw;
  try {
    raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw InputError(path, 0, std::string("cannot be read as an image: ") + e.what());
  }
  if (raw.empty()) throw InputError(path, 0, "cannot be read as an image");
  if (raw.cols != cam.width || raw.rows != cam.height) {
    throw InputError(path,
                     0,
                     "image is " + std::to_string(raw.cols) + "x" + std::to_string(raw.rows) +
                         " pixels but cam0/sensor.yaml gives resolution " +
                         std::to_string(cam.width) + "x" + std::to_string(cam.height));
  }
  cv::Mat grey;
  std::string why;
  if (!to_grey8(raw, cam.pixel_format, grey, &why)) throw InputError(path, 0, why);
  return grey;
}

WheelSensor load_wheel_sensor(const std::string& path) {
  const YAML::Node root = yaml::load_file(path);
  WheelSensor s;
  s.wheel_base = yaml::required_number(root, "wheel_base", path, true);
  if (!(s.wheel_base > 0)) {
    throw InputError(
        path, yaml::line_of(root["wheel_base"]), "field 'wheel_base' must be positive");
  }
  const std::string unit = yaml::optional_string(root, "unit", path).value_or("meters");
  if (unit == "meters") {
    s.unit = WheelUnit::kMeters;
  } else if (unit == "ticks") {
    s.unit = WheelUnit::kTicks;
  } else {
    throw InputError(path,
                     yaml::line_of(root["unit"]),
                     "field 'unit' must be meters or ticks, got '" + unit + "'");
  }
  if (s.unit == WheelUnit::kTicks) {
    for (const char* key : {"ticks_per_meter_left", "ticks_per_meter_right"}) {
      const double v = yaml::required_number(root, key, path, true);
      if (!(v > 0))
        throw InputError(
            path, yaml::line_of(root[key]), std::string("field '") + key + "' must be positive");
      (std::string(key) == "ticks_per_meter_left" ? s.ticks_per_meter_left
                                                  : s.ticks_per_meter_right) = v;
    }
  }
  if (const auto bits = yaml::optional_number(root, "counter_bits", path, true)) {
    if (*bits != std::floor(*bits) || *bits < 2 || *bits > 63) {
      throw InputError(path,
                       yaml::line_of(root["counter_bits"]),
                       "field 'counter_bits' must be a whole number in 2..63");
    }
    if (s.unit != WheelUnit::kTicks) {
      throw InputError(
          path, yaml::line_of(root["counter_bits"]), "field 'counter_bits' needs 'unit: ticks'");
    }
    s.counter_bits = static_cast<int>(*bits);
  }
  s.odometry_k = yaml::optional_number(root, "odometry_k", path, true);
  return s;
}

std::vector<WheelRecord> load_wheel_data(const std::string& path,
                                         const WheelSensor& s,
                                         double max_speed,
                                         std::vector<std::string>* notes) {
  std::string header;
  const auto rows = read_csv(path, 3, "timestamp [ns], left, right", &header, notes);
  const bool header_ticks = header.find("[ticks]") != std::string::npos;
  const bool header_meters = header.find("[m]") != std::string::npos;
  if (s.unit == WheelUnit::kMeters && header_ticks) {
    throw InputError(path, 1, "header says [ticks] but wheel0/sensor.yaml says 'unit: meters'");
  }
  if (s.unit == WheelUnit::kTicks && header_meters) {
    throw InputError(path, 1, "header says [m] but wheel0/sensor.yaml says 'unit: ticks'");
  }
  if (rows.empty()) throw InputError(path, 0, "no wheel data rows");
  std::vector<WheelRecord> out;
  out.reserve(rows.size());
  const double modulus = s.counter_bits > 0 ? std::ldexp(1.0, s.counter_bits) : 0.0;
  double raw_prev[2] = {0, 0}, unwrapped[2] = {0, 0}, first[2] = {0, 0};
  const char* names[2] = {"left", "right"};
  const double tpm[2] = {s.ticks_per_meter_left, s.ticks_per_meter_right};
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const CsvRow& r = rows[i];
    WheelRecord rec;
    rec.line = r.line;
    rec.timestamp_ns = parse_timestamp(r.fields[0], path, r.line);
    if (i > 0)
      check_increasing(out.back().timestamp_ns, out.back().line, rec.timestamp_ns, path, r.line);
    double meters[2];
    for (int w = 0; w < 2; ++w) {
      const double raw =
          parse_double(r.fields[1 + w], std::string(names[w]) + " wheel value", path, r.line);
      if (i == 0) {
        unwrapped[w] = raw;
        first[w] = raw;
      } else {
        double d = raw - raw_prev[w];
        if (modulus > 0) {
          // Unwrap: the counter moved by the smallest step consistent with modular arithmetic.
          d = d - modulus * std::round(d / modulus);
        }
        unwrapped[w] += d;
        const double dt = static_cast<double>(rec.timestamp_ns - out.back().timestamp_ns) * 1e-9;
        const double dm = s.unit == WheelUnit::kTicks ? d / tpm[w] : d;
        if (std::abs(dm) > max_speed * dt + 1e-9) {
          std::string hint;
          if (s.unit == WheelUnit::kTicks && s.counter_bits == 0) {
            hint = "; if the tick counter wraps, give counter_bits in wheel0/sensor.yaml";
          } else if (s.unit == WheelUnit::kTicks) {
            hint = "; check counter_bits and ticks_per_meter in wheel0/sensor.yaml";
          }
          char buf[200];
          std::snprintf(
              buf,
              sizeof buf,
              "%s wheel jumps by %.4g m in %.4g s (%.3g m/s, more than the plausible %.3g m/s)",
              names[w],
              dm,
              dt,
              std::abs(dm) / std::max(dt, 1e-12),
              max_speed);
          throw InputError(path, r.line, buf + hint);
        }
      }
      raw_prev[w] = raw;
      meters[w] = (unwrapped[w] - first[w]) / (s.unit == WheelUnit::kTicks ? tpm[w] : 1.0);
    }
    rec.travel = {meters[0], meters[1]};
    out.push_back(rec);
  }
  return out;
}

// A ground-truth row's frame must index cam0/data.csv.
void check_frame_index(int frame, std::size_t images, const std::string& path, int line) {
  if (frame < 0 || static_cast<std::size_t>(frame) >= images) {
    throw InputError(path,
                     line,
                     "frame " + std::to_string(frame) + " is not an image index (0.." +
                         std::to_string(static_cast<long>(images) - 1) + ")");
  }
}

GroundTruth load_ground_truth(const std::string& dir,
                              const std::vector<ImageRecord>& images,
                              bool with_lines,
                              std::vector<std::string>* notes) {
  GroundTruth gt;
  std::error_code ec;
  const std::string ext = rel(dir, "extrinsics.yaml");
  if (fs::exists(ext, ec)) {
    const YAML::Node root = yaml::load_file(ext);
    Extrinsics x;
    x.phi = yaml::required_number(root, "phi", ext);
    x.rho = yaml::required_number(root, "rho", ext, true);
    x.psi = yaml::required_number(root, "psi", ext);
    gt.extrinsics = x;
  }
  const std::string poses = rel(dir, "poses.csv");
  if (fs::exists(poses, ec)) {
    gt.has_poses = true;
    int prev_line = 0;
    for (const CsvRow& r :
         read_csv(poses, 4, "timestamp [ns], x [m], y [m], theta [rad]", nullptr, notes)) {
      PoseRecord p;
      p.timestamp_ns = parse_timestamp(r.fields[0], poses, r.line);
      if (!gt.poses.empty())
        check_increasing(gt.poses.back().timestamp_ns, prev_line, p.timestamp_ns, poses, r.line);
      p.x = parse_double(r.fields[1], "x", poses, r.line);
      p.y = parse_double(r.fields[2], "y", poses, r.line);
      p.theta = parse_double(r.fields[3], "theta", poses, r.line);
      gt.poses.push_back(p);
      prev_line = r.line;
    }
  }
  const std::string lines = rel(dir, "lines.csv");
  if (with_lines && fs::exists(lines, ec)) {
    gt.has_lines = true;
    for_each_csv_row(
        lines,
        6,
        "timestamp [ns], frame, line_id, bearing [rad], r_inner [px], r_outer [px]",
        nullptr,
        notes,
        [&](const CsvRow& r) {
          LineRecord l;
          l.timestamp_ns = parse_timestamp(r.fields[0], lines, r.line);
          l.frame = parse_int(r.fields[1], "frame", lines, r.line);
          l.line_id = parse_int(r.fields[2], "line_id", lines, r.line);
          l.bearing = parse_double(r.fields[3], "bearing", lines, r.line);
          l.r_inner = parse_double(r.fields[4], "r_inner", lines, r.line);
          l.r_outer = parse_double(r.fields[5], "r_outer", lines, r.line);
          check_frame_index(l.frame, images.size(), lines, r.line);
          if (images[static_cast<std::size_t>(l.frame)].timestamp_ns != l.timestamp_ns) {
            throw InputError(lines,
                             r.line,
                             "timestamp " + std::to_string(l.timestamp_ns) +
                                 " is not that of frame " + std::to_string(l.frame) +
                                 " in cam0/data.csv");
          }
          if (!gt.lines.empty() && l.frame < gt.lines.back().frame) {
            throw InputError(lines, r.line, "frames must not decrease");
          }
          gt.lines.push_back(l);
        });
    gt.line_offsets.assign(images.size() + 1, 0);
    for (const LineRecord& l : gt.lines) ++gt.line_offsets[static_cast<std::size_t>(l.frame) + 1];
    for (std::size_t k = 1; k < gt.line_offsets.size(); ++k)
      gt.line_offsets[k] += gt.line_offsets[k - 1];
  }
  const std::string occluders = rel(dir, "occluders.csv");
  if (fs::exists(occluders, ec)) {
    for (const CsvRow& r :
         read_csv(occluders, 4, "timestamp [ns], frame, occluder, bearing [rad]", nullptr, notes)) {
      OccluderEdge o;
      o.timestamp_ns = parse_timestamp(r.fields[0], occluders, r.line);
      o.frame = parse_int(r.fields[1], "frame", occluders, r.line);
      o.occluder = parse_int(r.fields[2], "occluder", occluders, r.line);
      o.bearing = parse_double(r.fields[3], "bearing", occluders, r.line);
      check_frame_index(o.frame, images.size(), occluders, r.line);
      gt.occluders.push_back(o);
    }
  }
  return gt;
}

}  // namespace

Dataset Dataset::load(const std::string& dir, const LoadOptions& options) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir, 0, "dataset directory not found");
  Dataset d;
  d.root_ = dir;
  d.camera_ = load_camera_geometry(rel(dir, "cam0/sensor.yaml"));

  // Images.
  const std::string cam_csv = rel(dir, "cam0/data.csv");
  for (const CsvRow& r : read_csv(cam_csv, 2, "timestamp [ns], filename", nullptr, &d.notes_)) {
    ImageRecord im;
    im.line = r.line;
    im.timestamp_ns = parse_timestamp(r.fields[0], cam_csv, r.line);
    if (!d.images_.empty())
      check_increasing(
          d.images_.back().timestamp_ns, d.images_.back().line, im.timestamp_ns, cam_csv, r.line);
    im.filename = r.fields[1];
    if (im.filename.empty()) throw InputError(cam_csv, r.line, "empty file name");
    im.path = rel(dir, "cam0/data/" + im.filename);
    if (!fs::is_regular_file(im.path, ec)) {
      if (!options.allow_missing_images) {
        throw InputError(
            cam_csv, r.line, "image file '" + im.filename + "' not found in cam0/data/");
      }
      im.missing = true;
    }
    d.images_.push_back(std::move(im));
  }
  if (d.images_.empty()) throw InputError(cam_csv, 0, "no images listed");
  const auto first_present = std::find_if(
      d.images_.begin(), d.images_.end(), [](const ImageRecord& im) { return !im.missing; });
  if (first_present == d.images_.end()) {
    throw InputError(cam_csv,
                     0,
                     "none of the " + std::to_string(d.images_.size()) +
                         " listed image files exists in cam0/data/");
  }
  if (options.check_all_images) {
    for (std::size_t i = 0; i < d.images_.size(); ++i) {
      if (!d.images_[i].missing) (void)d.image(i);
    }
  } else {
    (void)d.image(static_cast<std::size_t>(first_present - d.images_.begin()));
  }

  // Wheels.
  const std::string wheel_dir = rel(dir, "wheel0");
  if (options.require_wheel || fs::exists(wheel_dir, ec)) {
    d.wheel_sensor_ = load_wheel_sensor(rel(dir, "wheel0/sensor.yaml"));
    const std::string wheel_csv = rel(dir, "wheel0/data.csv");
    d.wheel_ = load_wheel_data(wheel_csv, d.wheel_sensor_, options.max_wheel_speed, &d.notes_);
    const std::int64_t w0 = d.wheel_.front().timestamp_ns, w1 = d.wheel_.back().timestamp_ns;
    for (const ImageRecord& im : d.images_) {
      if (im.timestamp_ns < w0 || im.timestamp_ns > w1) {
        throw InputError(wheel_csv,
                         0,
                         "wheel data (timestamps " + std::to_string(w0) + " to " +
                             std::to_string(w1) + ") does not cover the image at line " +
                             std::to_string(im.line) + " of cam0/data.csv (timestamp " +
                             std::to_string(im.timestamp_ns) + ")");
      }
    }
    d.travel_at_images_.reserve(d.images_.size());
    for (const ImageRecord& im : d.images_)
      d.travel_at_images_.push_back(d.travel_at(im.timestamp_ns));
  }

  // Ground truth: optional, and needed only to evaluate; one that cannot be read is recorded
  // (ground_truth_error) for the tools that use it, and does not stop the others.
  const std::string gt_dir = rel(dir, "ground_truth");
  if (fs::is_directory(gt_dir, ec)) {
    try {
      d.ground_truth_ = load_ground_truth(gt_dir, d.images_, options.ground_truth_lines, &d.notes_);
    } catch (const InputError& e) {
      d.ground_truth_error_ = e.what();
    }
  }
  return d;
}

cv::Mat1b Dataset::image(std::size_t i) const {
  if (i >= images_.size()) throw std::out_of_range("image index out of range");
  const ImageRecord& im = images_[i];
  if (im.missing) {
    throw InputError(rel(root_, "cam0/data.csv"),
                     im.line,
                     "image file '" + im.filename + "' not found in cam0/data/");
  }
  return read_checked_image(im.path, camera_);
}

int Dataset::set_image_time_offset(std::int64_t offset_ns) {
  image_time_offset_ns_ = offset_ns;
  if (wheel_.empty()) return 0;
  int outside = 0;
  travel_at_images_.clear();
  for (std::size_t i = 0; i < images_.size(); ++i) {
    outside += image_outside_wheel_data(i) ? 1 : 0;
    travel_at_images_.push_back(travel_at(
        std::clamp(odometry_time(i), wheel_.front().timestamp_ns, wheel_.back().timestamp_ns)));
  }
  return outside;
}

WheelTravel Dataset::travel_at(std::int64_t t) const {
  if (wheel_.empty() || t < wheel_.front().timestamp_ns || t > wheel_.back().timestamp_ns) {
    throw std::out_of_range("timestamp outside the wheel data");
  }
  auto it =
      std::lower_bound(wheel_.begin(), wheel_.end(), t, [](const WheelRecord& w, std::int64_t v) {
        return w.timestamp_ns < v;
      });
  if (it->timestamp_ns == t) return it->travel;
  const WheelRecord& b = *it;
  const WheelRecord& a = *(it - 1);
  const double f = static_cast<double>(t - a.timestamp_ns) /
                   static_cast<double>(b.timestamp_ns - a.timestamp_ns);
  return {a.travel.left + f * (b.travel.left - a.travel.left),
          a.travel.right + f * (b.travel.right - a.travel.right)};
}

}  // namespace omnivert::dataset
