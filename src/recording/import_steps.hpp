#pragma once
// The steps of import_recording (import.hpp): checking the topics, the pass over the
// recording, the clocks' overlap, cam0/sensor.yaml.

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/recording/import.hpp"

namespace omnivert::recording {

// Throws InputError when the recording has no topic `name` (listing the topics it has) or
// when its type is none of `types` (normalised: sensor_msgs/Image).
void require_topic(const Recording& rec,
                   const std::string& name,
                   const std::vector<std::string>& types);

struct Collected {
  std::vector<std::pair<std::int64_t, std::string>> images;  // stamp, file name in cam0/data
  std::vector<dataset::WheelRecord> wheel;                   // from joint states
  std::vector<dataset::PoseRecord> poses;                    // from odometry
  int width = 0, height = 0;
  std::string encoding;
  PixelFormat pixel;
};

// The one pass: images written to `data_dir`, odometry kept.
Collected collect(Recording& rec,
                  const ImportOptions& o,
                  const std::filesystem::path& data_dir,
                  ImportSummary& s);

// Drops (and deletes) the images outside the odometry's time span; throws InputError when no
// image is inside it (the clocks do not overlap).
void keep_overlap(const Recording& rec,
                  const ImportOptions& o,
                  const std::vector<dataset::WheelRecord>& wheel,
                  Collected& c,
                  const std::filesystem::path& data_dir,
                  ImportSummary& s);

std::string odometry_provenance(const Recording& rec, const ImportOptions& o);

// cam0/sensor.yaml: a copy of options.camera_sensor (checked against the images' size, its
// mask copied too) or the resolution and pixel format alone.
void write_camera_sensor(const Recording& rec,
                         const ImportOptions& o,
                         const Collected& c,
                         const std::filesystem::path& cam_dir);

}  // namespace omnivert::recording
