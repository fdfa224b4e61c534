#include "omnivert/recording/messages.hpp"

#include "recording/bytes.hpp"

namespace omnivert::recording {

namespace {

// ROS 1: packed little endian, strings and sequences <u32 length><items>, time <u32 s><u32 ns>.
// CDR (XCDR1, as rosbag2 writes): <encapsulation: 0x00 0x01 options u16>, then each primitive
// aligned to its size relative to the end of the encapsulation header; strings
// <u32 length with the NUL><chars><NUL>; time <i32 s><u32 ns>.
class Decoder {
 public:
  Decoder(std::span<const std::uint8_t> bytes, Serialization s, const std::string& what)
      : r_(bytes, what), cdr_(s == Serialization::kCdr) {
    if (cdr_) {
      const auto kind = r_.bytes(4);
      if (kind[1] != 0x01) {
        r_.fail("CDR encapsulation " + std::to_string(kind[0]) + "," + std::to_string(kind[1]) +
                " is not little-endian plain CDR");
      }
    }
  }
  template <typename T>
  T get() {
    align(sizeof(T));
    return r_.get<T>();
  }
  std::string string() {
    const auto n = get<std::uint32_t>();
    std::string s = r_.string(n);
    if (cdr_ && !s.empty() && s.back() == '\0') s.pop_back();
    return s;
  }
  std::int64_t stamp() {
    const auto sec = get<std::int32_t>();
    const auto nsec = get<std::uint32_t>();
    return static_cast<std::int64_t>(cdr_ ? sec : static_cast<std::uint32_t>(sec)) * 1'000'000'000 +
           nsec;
  }
  // std_msgs/Header: ROS 1 has a sequence number first.
  std::int64_t header(std::string* frame_id = nullptr) {
    if (!cdr_) get<std::uint32_t>();
    const std::int64_t t = stamp();
    std::string f = string();
    if (frame_id) *frame_id = std::move(f);
    return t;
  }
  std::span<const std::uint8_t> byte_sequence() {
    const auto n = get<std::uint32_t>();
    return r_.bytes(n);
  }
  std::vector<double> doubles() {
    const auto n = get<std::uint32_t>();
    r_.need(static_cast<std::size_t>(n) * 8);
    std::vector<double> v(n);
    for (auto& x : v) x = get<double>();
    return v;
  }
  std::vector<std::string> strings() {
    const auto n = get<std::uint32_t>();
    r_.need(n);  // at least a length each
    std::vector<std::string> v(n);
    for (auto& s : v) s = string();
    return v;
  }

 private:
  void align(std::size_t n) {
    if (!cdr_) return;
    const std::size_t off = r_.pos() - 4;
    if (off % n) r_.bytes(n - off % n);
  }
  ByteReader r_;
  bool cdr_;
};

}  // namespace

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
