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
#include "omnivert/recording/messages.hpp"

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
  std::string camera_frame_id;          // the images' header.frame_id
  std::vector<TransformMsg> tf_static;  // of /tf_static, in the recording's order
  std::string robot_description;        // the last /robot_description
};

// The description's topics, read when the recording has them with these types.
inline constexpr const char* kTfStaticTopic = "/tf_static";
inline constexpr const char* kRobotDescriptionTopic = "/robot_description";
// Whether the recording has topic `name` of type `type` (normalised) with messages.
bool has_topic(const Recording& rec, const std::string& name, const std::string& type);

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

// The robot's description (import_description.cpp): a wheel base or wheel radius of 0 in `o`
// taken from /robot_description (with the wheel joints' names), the camera's mount from
// /tf_static (base_frame -> camera_frame), each recorded in `s`.
void use_description(const Recording& rec, const Collected& c, ImportOptions& o, ImportSummary& s);

// prior.yaml of the dataset: the mount of `s` as the keys of `calibrate --prior`.
std::string prior_yaml(const ImportSummary& s);

// Joint-state travel collected with a wheel radius of 1 (the radius unknown during the pass)
// scaled by o.wheel_radius, and then checked against o.max_speed.
void scale_wheel_travel(const Recording& rec,
                        const ImportOptions& o,
                        std::vector<dataset::WheelRecord>& wheel);

}  // namespace omnivert::recording
