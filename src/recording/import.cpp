#include "omnivert/recording/import.hpp"
#include "omnivert/recording/laser_scan.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "omnivert/core/error.hpp"
#include "omnivert/dataset/poses_to_wheels.hpp"
#include "omnivert/dataset/writer.hpp"
#include "recording/import_steps.hpp"

namespace omnivert::recording {

namespace fs = std::filesystem;

std::string topics_table(const Recording& rec) {
  std::size_t w = 5, t = 4;
  for (const TopicInfo& i : rec.topics()) {
    w = std::max(w, i.name.size());
    t = std::max(t, i.type.size());
  }
  std::string out;
  char line[512];
  std::snprintf(line,
                sizeof line,
                "  %-*s  %-*s  %s\n",
                static_cast<int>(w),
                "topic",
                static_cast<int>(t),
                "type",
                "messages");
  out += line;
  for (const TopicInfo& i : rec.topics()) {
    std::snprintf(line,
                  sizeof line,
                  "  %-*s  %-*s  %llu\n",
                  static_cast<int>(w),
                  i.name.c_str(),
                  static_cast<int>(t),
                  i.type.c_str(),
                  static_cast<unsigned long long>(i.count));
    out += line;
  }
  return out;
}

namespace {

// The temporary folder beside `out`, removed unless released.
struct TempDir {
  fs::path path;
  bool keep = false;
  ~TempDir() {
    std::error_code ec;
    if (!keep && !path.empty()) fs::remove_all(path, ec);
  }
};

// The wheel base and the radius may come from /robot_description (use_description): they are
// checked once it has been read (check_wheels).
void check_options(const Recording& rec, const ImportOptions& o) {
  const int sources =
      !o.joint_states_topic.empty() + !o.odometry_topic.empty() + !o.poses_csv.empty();
  if (sources > 1) {
    throw InputError(
        "give one odometry source: --joint-states-topic, --odometry-topic or --poses-csv");
  }
  if (!o.joint_states_topic.empty() && (o.left_joint.empty() || o.right_joint.empty())) {
    throw InputError("--joint-states-topic needs --wheel-joints LEFT,RIGHT and --wheel-radius");
  }
  const bool desc = has_topic(rec, kRobotDescriptionTopic, "std_msgs/String");
  if (!desc && !o.joint_states_topic.empty() && !(o.wheel_radius > 0))
    throw InputError("--joint-states-topic needs --wheel-joints LEFT,RIGHT and --wheel-radius");
  if (!desc && sources == 1 && !(o.wheel_base > 0))
    throw InputError("--wheel-base is needed with odometry");
  require_topic(rec, o.image_topic, {"sensor_msgs/Image", "sensor_msgs/CompressedImage"});
  if (!o.joint_states_topic.empty())
    require_topic(rec, o.joint_states_topic, {"sensor_msgs/JointState"});
  if (!o.odometry_topic.empty()) require_topic(rec, o.odometry_topic, {"nav_msgs/Odometry"});
  if (!o.laser_topic.empty()) {
    if (!o.laser_pose)
      throw InputError("--laser-topic needs --laser-pose X Y YAW: the scanner's pose on the robot");
    require_topic(rec, o.laser_topic, {"sensor_msgs/LaserScan"});
  }
}

double seconds(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }

void check_wheels(const Recording& rec, const ImportOptions& o) {
  const std::string from =
      " (the recording's " + std::string(kRobotDescriptionTopic) +
      (o.left_joint.empty() ? " gives it with --wheel-joints LEFT,RIGHT)" : " does not give it)");
  // (Without /robot_description check_options has refused a missing wheel base or radius.)
  const bool odometry =
      !o.joint_states_topic.empty() || !o.odometry_topic.empty() || !o.poses_csv.empty();
  if (!o.joint_states_topic.empty() && !(o.wheel_radius > 0))
    throw InputError(rec.path(), 0, "--wheel-radius is needed with joint states" + from);
  if (odometry && !(o.wheel_base > 0))
    throw InputError(rec.path(), 0, "--wheel-base is needed with odometry" + from);
}

}  // namespace

ImportSummary import_recording(Recording& rec, const ImportOptions& options) {
  check_options(rec, options);
  ImportOptions o = options;  // the wheel base and radius completed by the description
  // "run/" names the folder run: its temporary sibling must not lie inside it.
  fs::path out = fs::absolute(o.out).lexically_normal();
  if (!out.has_filename() && out.has_parent_path()) out = out.parent_path();
  std::error_code ec;
  if (fs::exists(out, ec) && !o.overwrite) {
    throw InputError(out.string(), 0, "exists already (give --force to replace it)");
  }
  if (o.overwrite) dataset::check_replaceable(out);
  std::string hidden = ".";
  hidden += out.filename().string();
  hidden += ".import-";
  dataset::remove_stale_temporaries(out.parent_path(), hidden);
  hidden += std::to_string(getpid());
  TempDir tmp{out.parent_path() / hidden};
  fs::remove_all(tmp.path, ec);
  fs::create_directories(tmp.path / "cam0" / "data");

  ImportSummary s;
  s.format = rec.format();
  // Without a radius the joint angles are collected as they are, scaled and checked after the
  // pass (the description that gives the radius may come last).
  ImportOptions pass = o;
  const bool scale_later = !o.joint_states_topic.empty() && !(o.wheel_radius > 0);
  if (scale_later) pass.wheel_radius = 1.0, pass.max_speed = INFINITY;
  Collected c = collect(rec, pass, tmp.path / "cam0" / "data", s);
  use_description(rec, c, o, s);
  check_wheels(rec, o);
  if (scale_later) scale_wheel_travel(rec, o, c.wheel);
  s.wheel_base = o.wheel_base;
  s.wheel_radius = o.wheel_radius;

  std::vector<dataset::WheelRecord> wheel;
  const std::string odo_source = rec.path() + ", topic " + o.odometry_topic;
  if (!o.joint_states_topic.empty()) {
    wheel = std::move(c.wheel);
  } else if (!o.odometry_topic.empty()) {
    wheel = dataset::wheel_travel_from_poses(c.poses, {o.wheel_base, o.max_speed, odo_source});
  } else if (!o.poses_csv.empty()) {
    const auto poses = dataset::read_tum_poses(o.poses_csv);
    wheel = dataset::wheel_travel_from_poses(poses, {o.wheel_base, o.max_speed, o.poses_csv});
  }
  s.image_start_s = seconds(c.images.front().first);
  s.image_end_s = seconds(c.images.back().first);
  if (!wheel.empty()) {
    keep_overlap(rec, o, wheel, c, tmp.path / "cam0" / "data", s);
    fs::create_directories(tmp.path / "wheel0");
    dataset::WheelCsvWriter csv((tmp.path / "wheel0" / "data.csv").string(),
                                dataset::WheelUnit::kMeters);
    for (const auto& w : wheel) csv.add_meters(w.timestamp_ns, w.travel.left, w.travel.right);
    csv.close();
    dataset::WheelSensor ws;
    ws.wheel_base = o.wheel_base;
    ws.odometry_k = o.odometry_k;
    const double span = seconds(wheel.back().timestamp_ns - wheel.front().timestamp_ns);
    const double rate = span > 0 ? static_cast<double>(wheel.size() - 1) / span : 0.0;
    dataset::write_text_file((tmp.path / "wheel0" / "sensor.yaml").string(),
                             dataset::wheel_sensor_yaml(ws, rate, odometry_provenance(rec, o)));
    s.wheel_samples = wheel.size();
  }
  dataset::ImageCsvWriter cam((tmp.path / "cam0" / "data.csv").string());
  for (const auto& [t, name] : c.images) cam.add(t, name);
  cam.close();
  write_camera_sensor(rec, o, c, tmp.path / "cam0");
  if (s.mount) dataset::write_text_file((tmp.path / kPriorFile).string(), prior_yaml(s));
  s.images = c.images.size();
  if (!o.laser_topic.empty())
    s.laser_scans = import_laser_scans(rec, o.laser_topic, *o.laser_pose, tmp.path);

  dataset::replace_folder(tmp.path, out);
  tmp.keep = true;
  return s;
}

}  // namespace omnivert::recording
