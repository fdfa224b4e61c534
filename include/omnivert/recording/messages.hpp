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
  std::string frame_id;
  std::uint32_t height = 0, width = 0, step = 0;
  std::string encoding;
  bool big_endian = false;
  std::span<const std::uint8_t> data;  // points into the message bytes
};

// sensor_msgs/CompressedImage
struct CompressedImageMsg {
  std::int64_t stamp_ns = 0;
  std::string frame_id;
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

// geometry_msgs/TransformStamped, an item of tf2_msgs/TFMessage: the pose of frame `child` in
// frame `parent` (header.frame_id), which maps child coordinates into the parent's.
struct TransformMsg {
  std::int64_t stamp_ns = 0;
  std::string parent, child;
  double translation[3] = {0, 0, 0};  // x, y, z [m]
  double rotation[4] = {0, 0, 0, 1};  // quaternion x, y, z, w
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
// tf2_msgs/TFMessage (/tf_static): its transforms.
std::vector<TransformMsg> decode_tf_message(std::span<const std::uint8_t> bytes,
                                            Serialization s,
                                            const std::string& what);
// std_msgs/String (/robot_description: the URDF).
std::string decode_string(std::span<const std::uint8_t> bytes,
                          Serialization s,
                          const std::string& what);

}  // namespace omnivert::recording
