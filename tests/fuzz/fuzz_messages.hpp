#pragma once
// The message decoders and the image writer of `omnivert import` on one message, as the
// import runs them (src/recording/import_steps.cpp): shared by the recording and the message
// harnesses.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "fuzz_support.hpp"
#include "omnivert/recording/messages.hpp"
#include "omnivert/recording/recording.hpp"
#include "recording/image_sink.hpp"

namespace omnivert::fuzz {

enum class MessageKind { kImage, kCompressedImage, kJointState, kOdometry };

inline void decode_one(MessageKind kind, const recording::Message& m, recording::Serialization s) {
  namespace r = omnivert::recording;
  const std::string what = "fuzzed message";
  expect_input_error_or_success([&] {
    switch (kind) {
      case MessageKind::kImage:
      case MessageKind::kCompressedImage: {
        const std::filesystem::path dir = scratch() / "images";
        std::filesystem::create_directories(dir);
        r::ImageSink sink(dir, s, kind == MessageKind::kCompressedImage);
        std::string name;
        (void)sink.add(m, what, name);
        std::error_code ec;
        std::filesystem::remove(dir / name, ec);
        break;
      }
      case MessageKind::kJointState: {
        const r::JointStateMsg js = r::decode_joint_state(m.data, s, what);
        for (double p : js.position) (void)std::isfinite(p);
        break;
      }
      case MessageKind::kOdometry:
        (void)r::decode_odometry(m.data, s, what);
        break;
    }
  });
}

// One decoder input: the first byte chooses the message type and the serialisation, the
// rest is the message (fuzz_decoders.cpp; the regression test replays its crashing inputs).
inline void decode_selected(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return;
  const auto kind = static_cast<MessageKind>(data[0] % 4);
  const auto s =
      (data[0] / 4) % 2 ? recording::Serialization::kCdr : recording::Serialization::kRos1;
  recording::TopicInfo topic{"/fuzz", "fuzz", 1};
  recording::Message m;
  m.topic = &topic;
  m.log_time_ns = 1;
  m.data = {data + 1, size - 1};
  decode_one(kind, m, s);
}

// The decoder `omnivert import` uses for a topic type; false for the others.
inline bool kind_of(const std::string& type, MessageKind& kind) {
  const std::string t = recording::normalized_type(type);
  if (t == "sensor_msgs/Image") return kind = MessageKind::kImage, true;
  if (t == "sensor_msgs/CompressedImage") return kind = MessageKind::kCompressedImage, true;
  if (t == "sensor_msgs/JointState") return kind = MessageKind::kJointState, true;
  if (t == "nav_msgs/Odometry") return kind = MessageKind::kOdometry, true;
  return false;
}

// A recording file opened and every message of every topic decoded (fuzz_recording.cpp; the
// regression test replays its crashing inputs).
inline void read_recording(const std::string& path) {
  expect_input_error_or_success([&] {
    auto rec = recording::open_recording(path);
    std::vector<std::string> names;
    for (const auto& t : rec->topics()) names.push_back(t.name);
    rec->read(names, [&](const recording::Message& m) {
      MessageKind kind;
      if (m.topic && kind_of(m.topic->type, kind)) decode_one(kind, m, rec->serialization());
    });
  });
}

}  // namespace omnivert::fuzz
