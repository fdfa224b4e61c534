#pragma once
// The messages `omnivert import` reads, decoded from ROS 1 serialisation or CDR (ROS 2: a
// 4-byte encapsulation header, little endian, primitives aligned to their size counted from
// the end of that header). Only the fields the import uses are kept. Each decoder throws
// InputError naming `what` (recording, topic, message index) when the bytes do not hold the
// message.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "omnivert/recording/recording.hpp"

namespace omnivert::recording {

// sensor_msgs/Image
struct ImageMsg {
  std::int64_t stamp_ns = 0;
  std::uint32_t height = 0, width = 0, step = 0;
  std::string encoding;
  bool big_endian = false;
  std::span<const std::uint8_t> data;  // points into the message bytes
};

// sensor_msgs/CompressedImage
struct CompressedImageMsg {
  std::int64_t stamp_ns = 0;
  std::string format;
  std::span<const std::uint8_t> data;
};

// sensor_msgs/JointState (positions only)
struct JointStateMsg {
  std::int64_t stamp_ns = 0;
  std::vector<std::string> name;
  std::vector<double> position;
};

// nav_msgs/Odometry (the pose only)
struct OdometryMsg {
  std::int64_t stamp_ns = 0;
  double x = 0, y = 0, z = 0;
  double qx = 0, qy = 0, qz = 0, qw = 1;
};

ImageMsg decode_image(std::span<const std::uint8_t> bytes,
                      Serialization s,
                      const std::string& what);
CompressedImageMsg decode_compressed_image(std::span<const std::uint8_t> bytes,
                                           Serialization s,
                                           const std::string& what);
JointStateMsg decode_joint_state(std::span<const std::uint8_t> bytes,
                                 Serialization s,
                                 const std::string& what);
OdometryMsg decode_odometry(std::span<const std::uint8_t> bytes,
                            Serialization s,
                            const std::string& what);

}  // namespace omnivert::recording
