#pragma once
// Writing the dataset folder (layout in dataset.hpp, format in docs/dataset-format.md): the
// files every writer of datasets shares (`omnivert simulate`, `omnivert import`), one row at
// a time so that a long recording is never held in memory.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "omnivert/dataset/dataset.hpp"

namespace omnivert::dataset {

// A CSV file written row by row; throws InputError naming the file when it cannot be
// opened or written.
class CsvWriter {
 public:
  CsvWriter(std::string path, const std::string& header);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;
  // Writes a finished line (without the newline).
  void row(const std::string& line);
  // Flushes and closes; throws when a write failed.
  void close();
  std::FILE* file() { return f_; }

 private:
  std::string path_;
  std::FILE* f_ = nullptr;
};

// cam0/data.csv: "#timestamp [ns],filename".
class ImageCsvWriter {
 public:
  explicit ImageCsvWriter(const std::string& path);
  void add(std::int64_t timestamp_ns, const std::string& filename);
  void close() { csv_.close(); }

 private:
  CsvWriter csv_;
};

// wheel0/data.csv: "#timestamp [ns],left [m],right [m]" (cumulative travel, %.9f) or
// "#timestamp [ns],left [ticks],right [ticks]".
class WheelCsvWriter {
 public:
  WheelCsvWriter(const std::string& path, WheelUnit unit);
  void add_meters(std::int64_t timestamp_ns, double left, double right);
  void add_ticks(std::int64_t timestamp_ns, std::int64_t left, std::int64_t right);
  void close() { csv_.close(); }

 private:
  CsvWriter csv_;
  WheelUnit unit_;
};

// wheel0/sensor.yaml: wheel_base, unit, ticks per meter and counter_bits (ticks),
// odometry_k when given, rate_hz when > 0; `provenance` is the first comment line.
std::string wheel_sensor_yaml(const WheelSensor& sensor,
                              double rate_hz,
                              const std::string& provenance);

// Writes `text` to `path`; throws InputError naming the file on failure (a full disk).
void write_text_file(const std::string& path, const std::string& text);

// What a writer's `--force` may replace: a folder named by its own name (not `.`, `..` or a
// path ending in a separator) that is empty or holds a dataset (cam0/data.csv). Throws
// InputError naming the folder otherwise, so that a mistyped --out never removes a folder
// of the user's.
void check_replaceable(const std::filesystem::path& out);

// Removes the siblings in `parent` named `prefix` followed by the process id of a process that
// no longer runs: the temporaries a killed writer left behind.
void remove_stale_temporaries(const std::filesystem::path& parent, const std::string& prefix);

// Puts the finished folder `tmp` in the place of `out` so that a kill at any moment leaves
// `out` either absent, the old dataset whole, or the new one whole: the old folder is first
// renamed to the hidden sibling `.NAME.replaced-PID` (removed afterwards, or by the next run
// when killed), then `tmp` is renamed to `out`.
void replace_folder(const std::filesystem::path& tmp, const std::filesystem::path& out);

}  // namespace omnivert::dataset
