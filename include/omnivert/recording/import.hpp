#pragma once
// A robot's recording turned into a dataset folder (dataset.hpp, docs/import.md): the images
// of one topic into cam0/, the odometry (wheel joint angles, odometry poses or a TUM pose
// file) into wheel0/ as wheel travel. One pass over the recording; the images are written as
// they come, the odometry (a few numbers per sample) is kept until the end.
//
// The dataset is written into a temporary folder beside `out` and renamed to `out` at the
// end, so a failure leaves no partial dataset. Bad input throws InputError naming the
// recording, the topic and the message index and time.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "omnivert/dataset/laser.hpp"
#include "omnivert/recording/recording.hpp"
#include "omnivert/recording/robot_description.hpp"

namespace omnivert::recording {

struct ImportOptions {
  std::string out;  // the dataset folder to write (must not exist unless overwrite)
  bool overwrite = false;
  std::string image_topic;  // sensor_msgs/Image or sensor_msgs/CompressedImage
  // Odometry, one of: JointState with the two wheel joints' angles [rad] times wheel_radius;
  std::string joint_states_topic;
  std::string left_joint, right_joint;
  double wheel_radius = 0;  // [m]
  // nav_msgs/Odometry poses;
  std::string odometry_topic;
  // a TUM pose file ("t x y z qx qy qz qw", t in seconds on the recording's clock).
  std::string poses_csv;
  // e [m], eq. (15): wheel0/sensor.yaml. 0: from /robot_description (with left_joint and
  // right_joint), as is a wheel_radius of 0.
  double wheel_base = 0;
  std::optional<double> odometry_k;  // Chong-Kleeman K [m], eq. (31), when known
  // A cam0/sensor.yaml to copy (centre, annulus, mask); without it only the resolution and
  // the pixel format are written and `omnivert camera` finds the rest.
  std::string camera_sensor;
  // sensor_msgs/LaserScan into laser0/ (recording/laser_scan.hpp), with the scanner's pose on
  // the robot (required with the topic: the message does not hold it).
  std::string laser_topic;
  std::optional<dataset::LaserSensor> laser_pose;
  // A pose step faster than this is an odometry jump [m/s].
  double max_speed = 5.0;
  // The frames of the camera's mount in /tf_static (docs/import.md#the-robots-description):
  // base_frame -> camera_frame becomes prior.yaml; an empty camera_frame is the images'
  // header.frame_id.
  std::string base_frame = "base_link";
  std::string camera_frame;
  ProgressFn progress;
};

struct ImportSummary {
  std::string format;              // of the recording
  std::size_t images = 0;          // written to cam0/
  std::size_t images_outside = 0;  // dropped: outside the odometry's time span
  std::size_t wheel_samples = 0;
  std::size_t laser_scans = 0;       // written to laser0/
  std::size_t duplicate_stamps = 0;  // odometry samples dropped for repeating the previous stamp
  std::string image_encoding;        // "mono8", "png", ...
  int width = 0, height = 0;
  double image_start_s = 0, image_end_s = 0, wheel_start_s = 0, wheel_end_s = 0;
  std::vector<std::string> warnings;
  // The camera's mount from /tf_static (written as prior.yaml) when the recording has the
  // transform; `mount_source` names it, or says why there is none.
  std::optional<CameraMount> mount;
  std::string base_frame, camera_frame, mount_source;
  // The wheel base and radius written, and whether they came from /robot_description.
  double wheel_base = 0, wheel_radius = 0;
  bool wheel_base_from_description = false, wheel_radius_from_description = false;
};

// The dataset's prior.yaml (docs/dataset-format.md#prior): the mount of the recording's
// /tf_static, which `calibrate` takes as its prior.
inline constexpr const char* kPriorFile = "prior.yaml";

// The topics of a recording as a table (name, type, messages), for --list and for messages.
std::string topics_table(const Recording& rec);

ImportSummary import_recording(Recording& rec, const ImportOptions& options);

}  // namespace omnivert::recording
