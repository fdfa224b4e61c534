#include "omnivert/recording/messages.hpp"

#include "recording/decoder.hpp"

namespace omnivert::recording {

ImageMsg decode_image(std::span<const std::uint8_t> bytes,
                      Serialization s,
                      const std::string& what) {
  Decoder d(bytes, s, what + " (sensor_msgs/Image)");
  ImageMsg m;
  m.stamp_ns = d.header(&m.frame_id);
  m.height = d.get<std::uint32_t>();
  m.width = d.get<std::uint32_t>();
  m.encoding = d.string();
  m.big_endian = d.get<std::uint8_t>() != 0;
  m.step = d.get<std::uint32_t>();
  m.data = d.byte_sequence();
  return m;
}

CompressedImageMsg decode_compressed_image(std::span<const std::uint8_t> bytes,
                                           Serialization s,
                                           const std::string& what) {
  Decoder d(bytes, s, what + " (sensor_msgs/CompressedImage)");
  CompressedImageMsg m;
  m.stamp_ns = d.header(&m.frame_id);
  m.format = d.string();
  m.data = d.byte_sequence();
  return m;
}

JointStateMsg decode_joint_state(std::span<const std::uint8_t> bytes,
                                 Serialization s,
                                 const std::string& what) {
  Decoder d(bytes, s, what + " (sensor_msgs/JointState)");
  JointStateMsg m;
  m.stamp_ns = d.header();
  m.name = d.strings();
  m.position = d.doubles();
  return m;
}

OdometryMsg decode_odometry(std::span<const std::uint8_t> bytes,
                            Serialization s,
                            const std::string& what) {
  Decoder d(bytes, s, what + " (nav_msgs/Odometry)");
  OdometryMsg m;
  m.stamp_ns = d.header();
  d.string();  // child_frame_id
  m.x = d.get<double>();
  m.y = d.get<double>();
  m.z = d.get<double>();
  m.qx = d.get<double>();
  m.qy = d.get<double>();
  m.qz = d.get<double>();
  m.qw = d.get<double>();
  return m;
}

std::vector<TransformMsg> decode_tf_message(std::span<const std::uint8_t> bytes,
                                            Serialization s,
                                            const std::string& what) {
  Decoder d(bytes, s, what + " (tf2_msgs/TFMessage)");
  const auto n = d.get<std::uint32_t>();
  std::vector<TransformMsg> v;
  for (std::uint32_t i = 0; i < n; ++i) {
    TransformMsg t;  // geometry_msgs/TransformStamped
    t.stamp_ns = d.header(&t.parent);
    t.child = d.string();
    for (double& x : t.translation) x = d.get<double>();
    for (double& x : t.rotation) x = d.get<double>();
    v.push_back(std::move(t));
  }
  return v;
}

std::string decode_string(std::span<const std::uint8_t> bytes,
                          Serialization s,
                          const std::string& what) {
  Decoder d(bytes, s, what + " (std_msgs/String)");
  return d.string();
}

}  // namespace omnivert::recording
