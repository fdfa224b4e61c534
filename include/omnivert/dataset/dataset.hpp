#pragma once
// The dataset reader every omnivert tool uses. Layout (EuRoC-style, written by
// `omnivert simulate`, format in docs/simulator.md):
//
//   cam0/data.csv        #timestamp [ns],filename          (images, 8-bit grey PNG or similar)
//   cam0/data/<file>
//   cam0/sensor.yaml     resolution, center, r_min, r_max, bearing_sign (core/camera_geometry.hpp)
//   wheel0/data.csv      #timestamp [ns],left [m],right [m]   (cumulative travel; or [ticks])
//   wheel0/sensor.yaml   wheel_base, unit: meters|ticks, ticks_per_meter_left/right,
//                        counter_bits, odometry_k
//   ground_truth/        optional: extrinsics.yaml (phi, rho, psi), poses.csv, lines.csv
//
// Dataset::load validates everything it reads and throws omnivert::InputError naming the
// file, the line and the problem: missing files, unparsable rows, duplicate or decreasing
// timestamps, image files that do not exist, wheel data that does not cover the images,
// implausible jumps of the wheel counters (wrapped counters are unwrapped when
// counter_bits is given).
//
// Images: load() checks that every listed image file exists and reads the first one to
// check its size and depth against cam0/sensor.yaml (all of them with
// LoadOptions::check_all_images). image(i) checks each image it reads, so a bad image later
// in the sequence is reported, with its file name, when a tool reaches it. With
// LoadOptions::allow_missing_images (what `omnivert track` uses) a listed file that does not
// exist is kept in images() with `missing` set, so frame indices and odometry stay aligned;
// image(i) then throws the InputError that load() would have thrown, for the caller to warn
// and skip the frame; the first image that exists is the one read on load.

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/core/camera_geometry.hpp"

namespace omnivert::dataset {

struct ImageRecord {
  std::int64_t timestamp_ns = 0;
  std::string filename;  // as listed in cam0/data.csv
  std::string path;      // full path
  int line = 0;          // line in cam0/data.csv
  bool missing = false;  // the file does not exist (LoadOptions::allow_missing_images)
};

enum class WheelUnit { kMeters, kTicks };

struct WheelSensor {
  double wheel_base = 0;  // e [m], eq. (15)
  WheelUnit unit = WheelUnit::kMeters;
  double ticks_per_meter_left = 0;
  double ticks_per_meter_right = 0;
  int counter_bits = 0;              // 0: counters do not wrap
  std::optional<double> odometry_k;  // Chong-Kleeman K [m], eq. (31)
};

// Cumulative travel of each wheel [m] since the first wheel sample.
struct WheelTravel {
  double left = 0;
  double right = 0;
};

struct WheelRecord {
  std::int64_t timestamp_ns = 0;
  WheelTravel travel;  // meters, counters unwrapped, relative to the first sample
  int line = 0;
};

struct Extrinsics {
  double phi = 0, rho = 0, psi = 0;
};

struct PoseRecord {
  std::int64_t timestamp_ns = 0;
  double x = 0, y = 0, theta = 0;
};

struct LineRecord {
  std::int64_t timestamp_ns = 0;
  int frame = 0;
  int line_id = 0;
  double bearing = 0;  // camera bearing [rad]
  double r_inner = 0, r_outer = 0;
};

// A side of a moving occluder (a person the simulator drew) in one frame: a vertical edge that
// belongs to no world line (ground_truth/occluders.csv, optional).
struct OccluderEdge {
  std::int64_t timestamp_ns = 0;
  int frame = 0;
  int occluder = 0;
  double bearing = 0;  // camera bearing [rad]
};

struct GroundTruth {
  std::optional<Extrinsics> extrinsics;
  std::vector<OccluderEdge> occluders;  // empty when occluders.csv is absent
  std::vector<PoseRecord> poses;        // empty when poses.csv is absent
  std::vector<LineRecord> lines;        // empty when lines.csv is absent
  bool has_poses = false;
  bool has_lines = false;
  // lines[line_offsets[k] .. line_offsets[k + 1]) are the lines of frame k (size: images + 1).
  std::vector<std::size_t> line_offsets;

  // The ground-truth lines of one frame (empty without lines.csv).
  std::span<const LineRecord> lines_in_frame(std::size_t frame) const {
    if (frame + 1 >= line_offsets.size()) return {};
    return {lines.data() + line_offsets[frame], line_offsets[frame + 1] - line_offsets[frame]};
  }
};

struct LoadOptions {
  // Read every image on load (slow for long sequences) instead of only the first.
  bool check_all_images = false;
  // Without wheel0/ the dataset still loads (images only) when this is false.
  bool require_wheel = true;
  // A listed image file that does not exist is an error when this is false; when true it is
  // recorded (ImageRecord::missing) and image(i) throws for it (at least one must exist).
  bool allow_missing_images = false;
  // A wheel moving faster than this between two samples is an error (a wrapped counter
  // without counter_bits, a glitch) [m/s].
  double max_wheel_speed = 5.0;
  // Read ground_truth/lines.csv (GroundTruth::lines). It is the largest file of a simulated
  // run (a million rows on a 2,367-frame tour) and only the evaluations and the map check use
  // it; without it has_lines is false.
  bool ground_truth_lines = true;
};

class Dataset {
 public:
  static Dataset load(const std::string& dir, const LoadOptions& options = {});

  const std::string& root() const { return root_; }
  const CameraGeometry& camera() const { return camera_; }
  const std::vector<ImageRecord>& images() const { return images_; }
  std::size_t size() const { return images_.size(); }

  // Reads image i as 8-bit grey (colour images are converted); throws InputError naming
  // the image file if it cannot be read, is not 8 bits deep or has the wrong size.
  cv::Mat1b image(std::size_t i) const;

  bool has_wheel() const { return !wheel_.empty(); }
  const WheelSensor& wheel_sensor() const { return wheel_sensor_; }
  const std::vector<WheelRecord>& wheel() const { return wheel_; }
  // Wheel travel interpolated (linearly) at a timestamp inside the wheel data; throws
  // std::out_of_range outside.
  WheelTravel travel_at(std::int64_t timestamp_ns) const;
  // Wheel travel at each image's odometry time (same order as images()).
  const std::vector<WheelTravel>& travel_at_images() const { return travel_at_images_; }

  // The camera-odometry time offset (docs/calibration.md#time-offset): positive when the
  // image stamps are late, so that image i was taken at odometry time
  // timestamp_ns - offset_ns. Recomputes travel_at_images(); an image whose odometry time
  // falls outside the wheel data gets the travel of the nearest end (its pose is not known:
  // image_outside_wheel_data(i)). Returns the number of such images. 0 after load.
  int set_image_time_offset(std::int64_t offset_ns);
  std::int64_t image_time_offset_ns() const { return image_time_offset_ns_; }
  // Image i's stamp on the odometry clock: images()[i].timestamp_ns - image_time_offset_ns(),
  // saturated at the limits of int64 (a stamp near them, shifted by the offset).
  std::int64_t odometry_time(std::size_t i) const {
    std::int64_t t = 0;
    if (__builtin_sub_overflow(images_[i].timestamp_ns, image_time_offset_ns_, &t)) {
      return image_time_offset_ns_ < 0 ? std::numeric_limits<std::int64_t>::max()
                                       : std::numeric_limits<std::int64_t>::min();
    }
    return t;
  }
  // Compared without overflow: stamps are >= 0 (load refuses negative ones).
  bool image_outside_wheel_data(std::size_t i) const {
    if (!has_wheel()) return false;
    const std::int64_t t = images_[i].timestamp_ns, off = image_time_offset_ns_;
    if (off >= 0) {
      return t - off < wheel_.front().timestamp_ns || t - off > wheel_.back().timestamp_ns;
    }
    return t < wheel_.front().timestamp_ns + off || t > wheel_.back().timestamp_ns + off;
  }

  // Empty when there is no ground_truth/ folder or when it could not be read; then
  // ground_truth_error() says why (file, line and problem) for the tools that need it.
  const std::optional<GroundTruth>& ground_truth() const { return ground_truth_; }
  const std::string& ground_truth_error() const { return ground_truth_error_; }
  // What loading noticed without refusing the data (columns of another tool beyond ours):
  // for the verbose log.
  const std::vector<std::string>& notes() const { return notes_; }

 private:
  std::string root_;
  CameraGeometry camera_;
  std::vector<ImageRecord> images_;
  WheelSensor wheel_sensor_;
  std::vector<WheelRecord> wheel_;
  std::vector<WheelTravel> travel_at_images_;
  std::int64_t image_time_offset_ns_ = 0;
  std::optional<GroundTruth> ground_truth_;
  std::string ground_truth_error_;
  std::vector<std::string> notes_;
};

}  // namespace omnivert::dataset
