// omnivert import RECORDING --out DATASET: a ROS 1 or ROS 2 recording turned into a dataset
// folder (docs/import.md). The library does the work (omnivert/recording/import.hpp).

#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include <spdlog/spdlog.h>

#include "commands.hpp"
#include "core/progress.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/recording/import.hpp"

namespace omnivert::cli {

namespace {

struct ImportArgs {
  std::string recording;
  bool list = false;
  std::string wheel_joints;
  double odometry_k = -1;
  std::vector<double> laser_pose;  // x, y, yaw
  recording::ImportOptions o;
};

void run_import(ImportArgs& a) {
  auto rec = recording::open_recording(a.recording);
  if (a.list) {
    std::printf("%s: %s\n%s",
                rec->path().c_str(),
                rec->format().c_str(),
                recording::topics_table(*rec).c_str());
    return;
  }
  if (a.o.out.empty()) throw InputError("--out is required (or --list)");
  if (a.o.image_topic.empty()) {
    throw InputError("--image-topic is required; the recording has:\n" +
                     recording::topics_table(*rec));
  }
  if (!a.wheel_joints.empty()) {
    const auto comma = a.wheel_joints.find(',');
    if (comma == std::string::npos)
      throw InputError("--wheel-joints: expected LEFT,RIGHT, got " + a.wheel_joints);
    a.o.left_joint = a.wheel_joints.substr(0, comma);
    a.o.right_joint = a.wheel_joints.substr(comma + 1);
  }
  if (a.odometry_k >= 0) a.o.odometry_k = a.odometry_k;
  if (a.laser_pose.size() == 3)
    a.o.laser_pose = dataset::LaserSensor{a.laser_pose[0], a.laser_pose[1], a.laser_pose[2], 0.0};
  std::unique_ptr<Progress> bar;
  a.o.progress = [&bar](std::uint64_t done, std::uint64_t total) {
    if (!bar) bar = std::make_unique<Progress>("import", static_cast<std::size_t>(total));
    bar->update(static_cast<std::size_t>(done));
  };
  const auto s = recording::import_recording(*rec, a.o);
  if (bar) bar->finish();
  for (const auto& w : s.warnings) spdlog::warn("{}", w);
  std::printf("%s: %zu images (%dx%d %s, %.3f to %.3f s)",
              s.format.c_str(),
              s.images,
              s.width,
              s.height,
              s.image_encoding.c_str(),
              s.image_start_s,
              s.image_end_s);
  if (s.wheel_samples > 0) {
    std::printf(
        ", %zu wheel samples (%.3f to %.3f s)", s.wheel_samples, s.wheel_start_s, s.wheel_end_s);
  }
  if (s.laser_scans > 0) std::printf(", %zu laser scans", s.laser_scans);
  std::printf("\nwrote %s\n", a.o.out.c_str());
}

}  // namespace

void add_import_command(CLI::App& app) {
  auto a = std::make_shared<ImportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "import",
      "Turn a ROS 1 bag or a ROS 2 bag (.db3, .mcap) into a dataset folder (docs/import.md)");
  cmd->add_option(
         "RECORDING", a->recording, "ROS 1 .bag, ROS 2 .db3 or .mcap file, or a ROS 2 bag folder")
      ->required();
  cmd->add_flag(
      "--list", a->list, "Print the recording's topics, types and message counts, and stop");
  cmd->add_option("--out", a->o.out, "Dataset folder to write (must not exist)");
  cmd->add_flag("--force", a->o.overwrite, "Replace the dataset folder if it exists");
  cmd->add_option(
      "--image-topic", a->o.image_topic, "sensor_msgs/Image or sensor_msgs/CompressedImage topic");
  cmd->add_option("--joint-states-topic",
                  a->o.joint_states_topic,
                  "sensor_msgs/JointState topic with the wheel angles [rad]");
  cmd->add_option("--wheel-joints", a->wheel_joints, "LEFT,RIGHT: the wheel joints' names");
  cmd->add_option(
         "--wheel-radius", a->o.wheel_radius, "Wheel radius [m] (with --joint-states-topic)")
      ->check(kPositive);
  cmd->add_option("--odometry-topic", a->o.odometry_topic, "nav_msgs/Odometry topic (poses)");
  cmd->add_option(
      "--poses-csv", a->o.poses_csv, "TUM pose file 't x y z qx qy qz qw' (t in seconds)");
  cmd->add_option("--wheel-base", a->o.wheel_base, "Distance between the wheels e [m], eq. (15)")
      ->check(kPositive);
  cmd->add_option(
         "--odometry-k", a->odometry_k, "Chong-Kleeman K [m], eq. (31), for wheel0/sensor.yaml")
      ->check(kNonNegative);
  cmd->add_option("--camera-sensor",
                  a->o.camera_sensor,
                  "A cam0/sensor.yaml to copy (centre, annulus, mask); default: resolution only");
  cmd->add_option("--max-speed",
                  a->o.max_speed,
                  "A pose or wheel step faster than this is refused as a jump or reset [m/s]")
      ->capture_default_str()
      ->check(kPositive);
  cmd->add_option("--laser-topic", a->o.laser_topic, "sensor_msgs/LaserScan topic, into laser0/");
  cmd->add_option(
         "--laser-pose", a->laser_pose, "The scanner's pose on the robot: X Y [m] YAW [rad]")
      ->expected(3);
  cmd->callback([a] { run_import(*a); });
}

}  // namespace omnivert::cli
