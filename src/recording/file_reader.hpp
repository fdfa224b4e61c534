#pragma once
// Positioned reads from a file, with messages naming the file; the readers load one record or
// chunk at a time with it.

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "omnivert/core/error.hpp"

namespace omnivert::recording {

class FileReader {
 public:
  explicit FileReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw InputError(path, 0, "cannot be opened for reading");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<std::uint64_t>(in_.tellg());
    in_.seekg(0);
  }
  std::uint64_t size() const { return size_; }
  const std::string& path() const { return path_; }
  // Reads n bytes at offset into out; throws naming `what` when the file ends first.
  void read(std::uint64_t offset,
            std::size_t n,
            std::vector<std::uint8_t>& out,
            const std::string& what) {
    if (offset > size_ || n > size_ - offset) {
      throw InputError(path_ + ": " + what + " at byte " + std::to_string(offset) + " needs " +
                       std::to_string(n) + " bytes but the file ends at " + std::to_string(size_) +
                       " (truncated recording?)");
    }
    out.resize(n);
    in_.seekg(static_cast<std::streamoff>(offset));
    in_.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(n));
    if (!in_) throw InputError(path_, 0, "read error at byte " + std::to_string(offset));
  }
  template <typename T>
  T value(std::uint64_t offset, const std::string& what) {
    read(offset, sizeof(T), scratch_, what);
    T v;
    std::memcpy(&v, scratch_.data(), sizeof(T));
    return v;
  }

 private:
  std::string path_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
  std::vector<std::uint8_t> scratch_;
};

}  // namespace omnivert::recording
