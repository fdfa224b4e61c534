#pragma once
// Recordings of a robot: ROS 1 bags (format 2.0: plain, bz2 and lz4 chunks) and ROS 2 bags
// (sqlite3 .db3, with per-message zstd; .mcap, with lz4 or zstd chunks), read in one pass,
// chunk by chunk, so that memory stays bounded whatever the recording's size
// (docs/import.md).
//
// open_recording reads only the recording's index or summary (topics, types, message
// counts); read() then hands each message of the chosen topics to a callback, in the order
// of the file, with its serialised bytes (ROS 1 serialisation or CDR, see encoding()).
// Every problem with the file throws omnivert::InputError naming the recording and what is
// wrong (a truncated file, an unknown compression, a record that does not parse).

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace omnivert::recording {

enum class Serialization { kRos1, kCdr };

struct TopicInfo {
  std::string name;
  std::string type;  // as the recording writes it: "sensor_msgs/Image", "sensor_msgs/msg/Image"
  std::uint64_t count = 0;
};

struct Message {
  const TopicInfo* topic = nullptr;
  std::int64_t log_time_ns = 0;        // when the recorder received it
  std::uint64_t index = 0;             // 0, 1, ... per topic, in file order
  std::span<const std::uint8_t> data;  // valid during the callback only
};

// (bytes read, bytes in total): for a progress bar.
using ProgressFn = std::function<void(std::uint64_t, std::uint64_t)>;
using MessageFn = std::function<void(const Message&)>;

class Recording {
 public:
  virtual ~Recording() = default;
  const std::string& path() const { return path_; }
  // "ROS 1 bag", "ROS 2 bag (sqlite3)", "MCAP".
  virtual std::string format() const = 0;
  virtual Serialization serialization() const = 0;
  const std::vector<TopicInfo>& topics() const { return topics_; }
  // nullptr when the recording has no such topic.
  const TopicInfo* find(const std::string& name) const;
  // The messages of `topics` (names) in file order.
  virtual void read(const std::vector<std::string>& topics,
                    const MessageFn& on_message,
                    const ProgressFn& progress = {}) = 0;

 protected:
  std::string path_;
  std::vector<TopicInfo> topics_;
};

// A ROS 1 bag (.bag), a ROS 2 bag file (.db3, .mcap) or a ROS 2 bag folder (metadata.yaml
// and one .db3 or .mcap file), by content (magic bytes) rather than by name.
std::unique_ptr<Recording> open_recording(const std::string& path);

// "sensor_msgs/msg/Image" -> "sensor_msgs/Image": ROS 1 and ROS 2 names compared alike.
std::string normalized_type(const std::string& type);

}  // namespace omnivert::recording
