#pragma once
// Little-endian byte reading and the decompressors (bz2, lz4 frames, zstd) the readers share.

#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "omnivert/core/error.hpp"

namespace omnivert::recording {

// A bounds-checked little-endian reader over a byte span; `what` names the data for messages.
class ByteReader {
 public:
  ByteReader(std::span<const std::uint8_t> data, std::string what)
      : data_(data), what_(std::move(what)) {}
  std::size_t pos() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }
  bool done() const { return pos_ >= data_.size(); }
  void seek(std::size_t p) {
    if (p > data_.size()) fail("offset past the end");
    pos_ = p;
  }
  template <typename T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::span<const std::uint8_t> bytes(std::size_t n) {
    need(n);
    auto s = data_.subspan(pos_, n);
    pos_ += n;
    return s;
  }
  std::string string(std::size_t n) {
    auto s = bytes(n);
    return std::string(reinterpret_cast<const char*>(s.data()), s.size());
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(what_ + ": " + why + " (at byte " + std::to_string(pos_) + ")");
  }
  void need(std::size_t n) const {
    if (n > remaining())
      fail("ends early, " + std::to_string(n) + " bytes needed and " + std::to_string(remaining()) +
           " left");
  }

 private:
  std::span<const std::uint8_t> data_;
  std::string what_;
  std::size_t pos_ = 0;
};

// Decompress into `out` (resized to `size`, the uncompressed size the container records);
// throws InputError with `what` when the data do not decompress to exactly that size.
void decompress_bz2(std::span<const std::uint8_t> in,
                    std::size_t size,
                    std::vector<std::uint8_t>& out,
                    const std::string& what);
void decompress_lz4_frame(std::span<const std::uint8_t> in,
                          std::size_t size,
                          std::vector<std::uint8_t>& out,
                          const std::string& what);
// size 0: unknown, taken from the frame (zstd records it).
void decompress_zstd(std::span<const std::uint8_t> in,
                     std::size_t size,
                     std::vector<std::uint8_t>& out,
                     const std::string& what);

}  // namespace omnivert::recording
