#include "omnivert/dataset/writer.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cinttypes>
#include <fstream>
#include <stdexcept>

#include "omnivert/core/error.hpp"

namespace omnivert::dataset {

namespace {

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

}  // namespace

CsvWriter::CsvWriter(std::string path, const std::string& header) : path_(std::move(path)) {
  f_ = std::fopen(path_.c_str(), "w");
  if (!f_)
    throw InputError(path_, 0, "cannot write (disk full, or a folder that is not writable?)");
  row(header);
}

CsvWriter::~CsvWriter() {
  if (f_) std::fclose(f_);
}

void CsvWriter::row(const std::string& line) {
  std::fputs(line.c_str(), f_);
  std::fputc('\n', f_);
}

void CsvWriter::close() {
  if (!f_) return;
  const bool bad = std::ferror(f_) != 0;
  const bool close_failed = std::fclose(f_) != 0;
  f_ = nullptr;
  if (bad || close_failed) throw InputError(path_, 0, "write error (disk full?)");
}

ImageCsvWriter::ImageCsvWriter(const std::string& path) : csv_(path, "#timestamp [ns],filename") {}

void ImageCsvWriter::add(std::int64_t timestamp_ns, const std::string& filename) {
  std::fprintf(csv_.file(), "%" PRId64 ",%s\n", timestamp_ns, filename.c_str());
}

WheelCsvWriter::WheelCsvWriter(const std::string& path, WheelUnit unit)
    : csv_(path,
           unit == WheelUnit::kTicks ? "#timestamp [ns],left [ticks],right [ticks]"
                                     : "#timestamp [ns],left [m],right [m]"),
      unit_(unit) {}

void WheelCsvWriter::add_meters(std::int64_t timestamp_ns, double left, double right) {
  if (unit_ != WheelUnit::kMeters) throw std::logic_error("wheel0/data.csv is in ticks");
  std::fprintf(csv_.file(), "%" PRId64 ",%.9f,%.9f\n", timestamp_ns, left, right);
}

void WheelCsvWriter::add_ticks(std::int64_t timestamp_ns, std::int64_t left, std::int64_t right) {
  if (unit_ != WheelUnit::kTicks) throw std::logic_error("wheel0/data.csv is in meters");
  std::fprintf(csv_.file(), "%" PRId64 ",%" PRId64 ",%" PRId64 "\n", timestamp_ns, left, right);
}

std::string wheel_sensor_yaml(const WheelSensor& s, double rate_hz, const std::string& provenance) {
  std::string y = "# " + provenance + "\n";
  y += "wheel_base: " + fmt("%.9g", s.wheel_base) + "   # e [m], eq. (15)\n";
  y += std::string("unit: ") + (s.unit == WheelUnit::kTicks ? "ticks" : "meters") + "\n";
  if (s.unit == WheelUnit::kTicks) {
    y += "ticks_per_meter_left: " + fmt("%.9g", s.ticks_per_meter_left) + "\n";
    y += "ticks_per_meter_right: " + fmt("%.9g", s.ticks_per_meter_right) + "\n";
    if (s.counter_bits > 0) y += "counter_bits: " + std::to_string(s.counter_bits) + "\n";
  }
  if (s.odometry_k) {
    y += "odometry_k: " + fmt("%.9g", *s.odometry_k) + "   # Chong-Kleeman K [m], eq. (31)\n";
  }
  if (rate_hz > 0) y += "rate_hz: " + fmt("%.9g", rate_hz) + "\n";
  return y;
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out)
    throw InputError(path, 0, "cannot write (disk full, or a folder that is not writable?)");
}

void check_replaceable(const std::filesystem::path& out) {
  namespace fs = std::filesystem;
  const std::string name = out.filename().string();
  if (name.empty() || name == "." || name == "..") {
    throw InputError(out.string(), 0, "give the output folder by its name to replace it");
  }
  std::error_code ec;
  if (!fs::exists(out, ec)) return;
  if (!fs::is_directory(out, ec)) {
    throw InputError(out.string(), 0, "is a file, not a dataset folder: not replaced");
  }
  if (fs::is_empty(out, ec) || fs::is_regular_file(out / "cam0" / "data.csv", ec)) return;
  throw InputError(out.string(),
                   0,
                   "is not a dataset folder (no cam0/data.csv): --force replaces only a dataset");
}

void remove_stale_temporaries(const std::filesystem::path& parent, const std::string& prefix) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string pid = name.substr(prefix.size());
    if (pid.empty() || pid.size() > 9 || pid.find_first_not_of("0123456789") != std::string::npos)
      continue;
    std::error_code rm;
    if (::kill(std::stoi(pid), 0) == -1 && errno == ESRCH) fs::remove_all(it->path(), rm);
  }
}

void replace_folder(const std::filesystem::path& tmp, const std::filesystem::path& out) {
  namespace fs = std::filesystem;
  fs::path parent = out.parent_path();
  if (parent.empty()) parent = ".";
  std::string prefix = ".";  // built in steps: GCC 12 warns falsely on "." + string + "..."
  prefix += out.filename().string();
  prefix += ".replaced-";
  remove_stale_temporaries(parent, prefix);
  std::error_code ec;
  if (!fs::exists(out, ec)) {
    fs::rename(tmp, out);
    return;
  }
  // Removing `out` in place would leave, when killed, a folder that is neither the old dataset
  // nor the new one (and that a rerun's --force then refuses as not a dataset).
  const fs::path old = parent / (prefix + std::to_string(::getpid()));
  fs::remove_all(old, ec);
  fs::rename(out, old);
  fs::rename(tmp, out);
  fs::remove_all(old, ec);
}

}  // namespace omnivert::dataset
