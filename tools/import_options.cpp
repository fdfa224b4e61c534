#include "import_options.hpp"

#include <cstdio>
#include <optional>

#include <spdlog/spdlog.h>

#include "commands.hpp"
#include "core/progress.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::cli {

void add_import_options(CLI::App* cmd, ImportFlags& f, bool job) {
  const std::string g = job ? kRecordingGroup : "Options";
  recording::ImportOptions& o = f.o;
  if (job) {
    cmd->add_flag("--keep-dataset",
                  f.keep_dataset,
                  "Keep the dataset imported from the recording in OUT/dataset (removed at the "
                  "end otherwise)")
        ->group(g);
  } else {
    cmd->add_option("--out", o.out, "Dataset folder to write (must not exist)");
    cmd->add_flag("--force", o.overwrite, "Replace the dataset folder if it exists");
  }
  cmd->add_option(
         "--image-topic", o.image_topic, "sensor_msgs/Image or sensor_msgs/CompressedImage topic")
      ->group(g);
  cmd->add_option("--joint-states-topic",
                  o.joint_states_topic,
                  "sensor_msgs/JointState topic with the wheel angles [rad]")
      ->group(g);
  cmd->add_option("--wheel-joints", f.wheel_joints, "LEFT,RIGHT: the wheel joints' names")
      ->group(g);
  cmd->add_option("--wheel-radius",
                  o.wheel_radius,
                  "Wheel radius [m] (with --joint-states-topic; default: from the recording's "
                  "/robot_description)")
      ->check(kPositive)
      ->group(g);
  cmd->add_option("--odometry-topic", o.odometry_topic, "nav_msgs/Odometry topic (poses)")
      ->group(g);
  cmd->add_option("--poses-csv", o.poses_csv, "TUM pose file 't x y z qx qy qz qw' (t in seconds)")
      ->group(g);
  cmd->add_option("--wheel-base",
                  o.wheel_base,
                  "Distance between the wheels e [m], eq. (15) (default: from the recording's "
                  "/robot_description)")
      ->check(kPositive)
      ->group(g);
  cmd->add_option(
         "--odometry-k", f.odometry_k, "Chong-Kleeman K [m], eq. (31), for wheel0/sensor.yaml")
      ->check(kNonNegative)
      ->group(g);
  cmd->add_option("--camera-sensor",
                  o.camera_sensor,
                  "A cam0/sensor.yaml to copy (centre, annulus, mask); default: resolution only")
      ->group(g);
  cmd->add_option("--max-speed",
                  o.max_speed,
                  "A pose or wheel step faster than this is refused as a jump or reset [m/s]")
      ->capture_default_str()
      ->check(kPositive)
      ->group(g);
  cmd->add_option("--laser-topic", o.laser_topic, "sensor_msgs/LaserScan topic, into laser0/")
      ->group(g);
  cmd->add_option(
         "--laser-pose", f.laser_pose, "The scanner's pose on the robot: X Y [m] YAW [rad]")
      ->expected(3)
      ->group(g);
}

recording::ImportOptions import_options(const ImportFlags& f) {
  recording::ImportOptions o = f.o;
  if (!f.wheel_joints.empty()) {
    const auto comma = f.wheel_joints.find(',');
    if (comma == std::string::npos)
      throw InputError("--wheel-joints: expected LEFT,RIGHT, got " + f.wheel_joints);
    o.left_joint = f.wheel_joints.substr(0, comma);
    o.right_joint = f.wheel_joints.substr(comma + 1);
  }
  if (f.odometry_k >= 0) o.odometry_k = f.odometry_k;
  if (f.laser_pose.size() == 3)
    o.laser_pose = dataset::LaserSensor{f.laser_pose[0], f.laser_pose[1], f.laser_pose[2], 0.0};
  return o;
}

std::unique_ptr<pipeline::ImportedDataset> import_for_job(CLI::App* cmd,
                                                          const std::string& input,
                                                          const std::string& out,
                                                          const ImportFlags& f) {
  if (!pipeline::is_recording(input)) {
    std::string given;
    for (const CLI::Option* o : cmd->get_options())
      if (o->count() > 0 && o->get_group() == kRecordingGroup)
        given += (given.empty() ? "" : ", ") + o->get_name();
    if (!given.empty())
      spdlog::warn("{} is a dataset folder: {} (options of a recording) did nothing", input, given);
    return nullptr;
  }
  recording::ImportOptions o = import_options(f);
  if (o.image_topic.empty()) {
    const auto rec = recording::open_recording(input);
    throw InputError("--image-topic is required with a recording; " + input + " has:\n" +
                     recording::topics_table(*rec));
  }
  std::optional<Progress> bar;
  o.progress = [&bar](std::uint64_t done, std::uint64_t total) {
    if (!bar) bar.emplace("import", static_cast<std::size_t>(total));
    bar->update(static_cast<std::size_t>(done));
  };
  auto d = std::make_unique<pipeline::ImportedDataset>(input, out, o, f.keep_dataset);
  if (bar) bar->finish();
  const recording::ImportSummary& s = d->summary();
  for (const auto& w : s.warnings) spdlog::warn("{}", w);
  std::printf("%s %s: %zu images (%dx%d %s), %zu wheel samples; dataset %s%s\n",
              s.format.c_str(),
              input.c_str(),
              s.images,
              s.width,
              s.height,
              s.image_encoding.c_str(),
              s.wheel_samples,
              d->path().c_str(),
              f.keep_dataset ? " (kept)" : " (removed at the end; --keep-dataset keeps it)");
  return d;
}

}  // namespace omnivert::cli
