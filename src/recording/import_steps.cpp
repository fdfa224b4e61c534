#include "recording/import_steps.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "omnivert/core/error.hpp"
#include "omnivert/dataset/poses_to_wheels.hpp"
#include "omnivert/dataset/writer.hpp"
#include "omnivert/recording/messages.hpp"
#include "recording/image_sink.hpp"

namespace omnivert::recording {

namespace fs = std::filesystem;

namespace {

std::string secs(std::int64_t ns) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9f s", static_cast<double>(ns) * 1e-9);
  return buf;
}

std::string describe(const Recording& rec, const Message& m) {
  return rec.path() + ", topic " + m.topic->name + ", message " + std::to_string(m.index) +
         " (recorded at " + secs(m.log_time_ns) + ")";
}

// Odometry stamps: later than the previous (true), equal (false: a duplicate to drop), or an
// InputError when earlier.
bool advances(std::int64_t t, std::int64_t previous, const std::string& what) {
  if (t > previous) return true;
  if (t == previous) return false;
  throw InputError(what + ": stamp " + secs(t) + " is before the previous message's " +
                   secs(previous) + " (stamps going backwards)");
}

struct JointIndex {
  std::vector<std::string> names;
  std::size_t left = 0, right = 0;
};

double joint_travel(const JointStateMsg& js,
                    const ImportOptions& o,
                    JointIndex& idx,
                    bool right,
                    const std::string& what) {
  if (js.name != idx.names) {
    auto find = [&](const std::string& n) {
      auto it = std::find(js.name.begin(), js.name.end(), n);
      if (it == js.name.end()) {
        std::string all;
        for (const auto& x : js.name) all += (all.empty() ? "" : ", ") + x;
        throw InputError(what + ": no joint '" + n + "' (joints: " + all + ")");
      }
      return static_cast<std::size_t>(it - js.name.begin());
    };
    idx.left = find(o.left_joint);
    idx.right = find(o.right_joint);
    idx.names = js.name;
  }
  const std::size_t k = right ? idx.right : idx.left;
  if (k >= js.position.size()) {
    throw InputError(what + ": " + std::to_string(js.position.size()) + " positions for " +
                     std::to_string(js.name.size()) + " joints");
  }
  return js.position[k] * o.wheel_radius;
}

// A wheel moving faster than o.max_speed between two joint states: the driver restarted
// (angles back to zero) or a glitch.
void check_wheel_step(const dataset::WheelRecord& prev,
                      std::int64_t t,
                      double left,
                      double right,
                      const ImportOptions& o,
                      const std::string& what) {
  const double dt = static_cast<double>(t - prev.timestamp_ns) * 1e-9;
  const double step =
      std::max(std::abs(left - prev.travel.left), std::abs(right - prev.travel.right));
  if (step > o.max_speed * dt) {
    char buf[160];
    std::snprintf(
        buf,
        sizeof buf,
        ": a wheel moves %.3f m in %.3f s, faster than %g m/s (a reset of the wheel angles?)",
        step,
        dt,
        o.max_speed);
    throw InputError(what + buf + "; import the parts before and after it separately");
  }
}

}  // namespace

bool has_topic(const Recording& rec, const std::string& name, const std::string& type) {
  const TopicInfo* t = rec.find(name);
  return t && t->count > 0 && normalized_type(t->type) == type;
}

void scale_wheel_travel(const Recording& rec,
                        const ImportOptions& o,
                        std::vector<dataset::WheelRecord>& wheel) {
  for (std::size_t i = 0; i < wheel.size(); ++i) {
    dataset::WheelRecord& w = wheel[i];
    w.travel.left *= o.wheel_radius;
    w.travel.right *= o.wheel_radius;
    if (i > 0) {
      check_wheel_step(
          wheel[i - 1],
          w.timestamp_ns,
          w.travel.left,
          w.travel.right,
          o,
          rec.path() + ", topic " + o.joint_states_topic + ", message " + std::to_string(w.line));
    }
  }
}

void require_topic(const Recording& rec,
                   const std::string& name,
                   const std::vector<std::string>& types) {
  const TopicInfo* t = rec.find(name);
  if (!t) {
    throw InputError(
        rec.path(), 0, "no topic '" + name + "'; the recording has:\n" + topics_table(rec));
  }
  const std::string type = normalized_type(t->type);
  if (std::find(types.begin(), types.end(), type) == types.end()) {
    std::string want;
    for (const auto& x : types) want += (want.empty() ? "" : " or ") + x;
    throw InputError(rec.path(), 0, "topic '" + name + "' is of type " + t->type + ", not " + want);
  }
  if (t->count == 0) throw InputError(rec.path(), 0, "topic '" + name + "' has no messages");
}

Collected collect(Recording& rec,
                  const ImportOptions& o,
                  const fs::path& data_dir,
                  ImportSummary& s) {
  Collected c;
  const bool compressed =
      normalized_type(rec.find(o.image_topic)->type) == "sensor_msgs/CompressedImage";
  ImageSink sink(data_dir, rec.serialization(), compressed);
  std::vector<std::string> topics = {o.image_topic};
  if (!o.joint_states_topic.empty()) topics.push_back(o.joint_states_topic);
  if (!o.odometry_topic.empty()) topics.push_back(o.odometry_topic);
  const bool tf = has_topic(rec, kTfStaticTopic, "tf2_msgs/TFMessage");
  const bool desc = has_topic(rec, kRobotDescriptionTopic, "std_msgs/String");
  if (tf) topics.push_back(kTfStaticTopic);
  if (desc) topics.push_back(kRobotDescriptionTopic);
  constexpr auto kNone = std::numeric_limits<std::int64_t>::min();
  std::int64_t last_odo = kNone;
  JointIndex idx;
  double left0 = 0, right0 = 0;
  std::size_t unstamped = 0;
  rec.read(
      topics,
      [&](const Message& m) {
        const std::string what = describe(rec, m);
        if (m.topic->name == o.image_topic) {
          std::string name;
          const std::int64_t t = sink.add(m, what, name);
          if (!c.images.empty() && t <= c.images.back().first) {
            throw InputError(what + ": image stamp " + secs(t) +
                             " is not after the previous image's " + secs(c.images.back().first) +
                             " (stamps going backwards)");
          }
          c.images.emplace_back(t, name);
        } else if (m.topic->name == o.joint_states_topic) {
          JointStateMsg js = decode_joint_state(m.data, rec.serialization(), what);
          if (js.stamp_ns == 0) js.stamp_ns = m.log_time_ns, ++unstamped;
          const double l = joint_travel(js, o, idx, false, what),
                       r = joint_travel(js, o, idx, true, what);
          if (!advances(js.stamp_ns, last_odo, what)) return void(++s.duplicate_stamps);
          if (c.wheel.empty()) left0 = l, right0 = r;
          if (!c.wheel.empty())
            check_wheel_step(c.wheel.back(), js.stamp_ns, l - left0, r - right0, o, what);
          last_odo = js.stamp_ns;
          c.wheel.push_back({js.stamp_ns, {l - left0, r - right0}, static_cast<int>(m.index)});
        } else if (m.topic->name == o.odometry_topic) {
          OdometryMsg od = decode_odometry(m.data, rec.serialization(), what);
          if (od.stamp_ns == 0) od.stamp_ns = m.log_time_ns, ++unstamped;
          if (!advances(od.stamp_ns, last_odo, what)) return void(++s.duplicate_stamps);
          last_odo = od.stamp_ns;
          c.poses.push_back(
              {od.stamp_ns, od.x, od.y, dataset::yaw_of_quaternion(od.qx, od.qy, od.qz, od.qw)});
        } else if (tf && m.topic->name == kTfStaticTopic) {
          for (auto& t : decode_tf_message(m.data, rec.serialization(), what))
            c.tf_static.push_back(std::move(t));
        } else if (desc && m.topic->name == kRobotDescriptionTopic) {
          c.robot_description = decode_string(m.data, rec.serialization(), what);
        }
      },
      o.progress);
  if (c.images.empty())
    throw InputError(rec.path(), 0, "topic '" + o.image_topic + "' has no messages");
  c.width = sink.width();
  c.height = sink.height();
  c.encoding = sink.encoding();
  c.pixel = sink.pixel_format();
  c.camera_frame_id = sink.frame_id();
  s.width = c.width;
  s.height = c.height;
  s.image_encoding = c.encoding;
  if (unstamped + sink.unstamped() > 0) {
    s.warnings.push_back(std::to_string(unstamped + sink.unstamped()) +
                         " message(s) had no header stamp (0); their recording time was used");
  }
  if (s.duplicate_stamps > 0) {
    s.warnings.push_back(std::to_string(s.duplicate_stamps) +
                         " odometry message(s) repeated the previous stamp and were dropped");
  }
  return c;
}

void keep_overlap(const Recording& rec,
                  const ImportOptions& o,
                  const std::vector<dataset::WheelRecord>& wheel,
                  Collected& c,
                  const fs::path& data_dir,
                  ImportSummary& s) {
  const std::int64_t w0 = wheel.front().timestamp_ns, w1 = wheel.back().timestamp_ns;
  s.wheel_start_s = static_cast<double>(w0) * 1e-9;
  s.wheel_end_s = static_cast<double>(w1) * 1e-9;
  std::vector<std::pair<std::int64_t, std::string>> kept;
  for (auto& im : c.images) {
    if (im.first >= w0 && im.first <= w1) {
      kept.push_back(std::move(im));
    } else {
      std::error_code ec;
      fs::remove(data_dir / im.second, ec);
      ++s.images_outside;
    }
  }
  const std::string odo = !o.joint_states_topic.empty() ? "topic " + o.joint_states_topic
                          : !o.odometry_topic.empty()   ? "topic " + o.odometry_topic
                                                        : o.poses_csv;
  if (kept.empty()) {
    throw InputError(rec.path() + ": the clocks do not overlap: the images of topic " +
                     o.image_topic + " run from " + secs(c.images.front().first) + " to " +
                     secs(c.images.back().first) + ", the odometry (" + odo + ") from " + secs(w0) +
                     " to " + secs(w1));
  }
  if (s.images_outside > 0) {
    s.warnings.push_back(std::to_string(s.images_outside) +
                         " image(s) outside the odometry's time span (" + secs(w0) + " to " +
                         secs(w1) + ") were left out");
  }
  c.images = std::move(kept);
}

std::string odometry_provenance(const Recording& rec, const ImportOptions& o) {
  std::string p = "omnivert import: wheel travel from ";
  if (!o.joint_states_topic.empty()) {
    char r[64];
    std::snprintf(r, sizeof r, "%.9g", o.wheel_radius);
    p += "the joint angles of " + o.left_joint + " and " + o.right_joint + " (topic " +
         o.joint_states_topic + ") times the wheel radius " + r + " m";
  } else if (!o.odometry_topic.empty()) {
    p += "the poses of topic " + o.odometry_topic + " through eqs. (14)-(15)";
  } else {
    p += "the poses of " + o.poses_csv + " through eqs. (14)-(15)";
  }
  return p + ", " + rec.path();
}

void write_camera_sensor(const Recording& rec,
                         const ImportOptions& o,
                         const Collected& c,
                         const fs::path& cam_dir) {
  const fs::path yaml = cam_dir / "sensor.yaml";
  if (!o.camera_sensor.empty()) {
    const CameraGeometry g = load_camera_geometry(o.camera_sensor);
    if (g.width != c.width || g.height != c.height) {
      throw InputError(o.camera_sensor,
                       0,
                       "resolution " + std::to_string(g.width) + "x" + std::to_string(g.height) +
                           " but the images of topic " + o.image_topic + " are " +
                           std::to_string(c.width) + "x" + std::to_string(c.height));
    }
    fs::copy_file(o.camera_sensor, yaml, fs::copy_options::overwrite_existing);
    if (g.mask)
      fs::copy_file(
          *g.mask, cam_dir / fs::path(*g.mask).filename(), fs::copy_options::overwrite_existing);
    return;
  }
  std::string y = "# omnivert import: images of topic " + o.image_topic + " (" + c.encoding +
                  ") in " + rec.path() + "\n";
  y += "# the centre and the annulus are estimated on each frame; `omnivert camera` finds them "
       "once\n";
  y += "resolution: [" + std::to_string(c.width) + ", " + std::to_string(c.height) + "]\n";
  if (c.pixel.bayer != BayerPattern::kNone)
    y += std::string("bayer: ") + bayer_pattern_name(c.pixel.bayer) + "\n";
  dataset::write_text_file(yaml.string(), y);
}

}  // namespace omnivert::recording
