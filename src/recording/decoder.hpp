#pragma once
// The field reader of the message decoders (messages.cpp, laser_scan.cpp): ROS 1 and CDR
// serialisations of the fields our messages use.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "omnivert/recording/messages.hpp"
#include "recording/bytes.hpp"

namespace omnivert::recording {

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
  // A sequence of numbers: <u32 length><items>.
  template <typename T>
  std::vector<T> numbers() {
    const auto n = get<std::uint32_t>();
    r_.need(static_cast<std::size_t>(n) * sizeof(T));
    std::vector<T> v(n);
    for (auto& x : v) x = get<T>();
    return v;
  }
  std::vector<double> doubles() { return numbers<double>(); }
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

}  // namespace omnivert::recording
