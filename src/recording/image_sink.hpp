#pragma once
// Image messages written as files of cam0/data/: raw sensor_msgs/Image as PNG (colour as
// BGR, Bayer and 16-bit kept as stored), sensor_msgs/CompressedImage's JPEG or PNG bytes as
// they are.

#include <cstdint>
#include <filesystem>
#include <string>

#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/recording/recording.hpp"

namespace omnivert::recording {

class ImageSink {
 public:
  ImageSink(std::filesystem::path dir, Serialization s, bool compressed)
      : dir_(std::move(dir)), serialization_(s), compressed_(compressed) {}
  // Writes the image of message m; returns its header stamp [ns]; `filename` gets the file's
  // name. `what` names the message for errors.
  std::int64_t add(const Message& m, const std::string& what, std::string& filename);

  int width() const { return width_; }
  int height() const { return height_; }
  const std::string& encoding() const { return encoding_; }
  const PixelFormat& pixel_format() const { return pixel_; }
  // Images whose header stamp was 0: their recording time was used instead.
  std::size_t unstamped() const { return unstamped_; }
  // The first image's header.frame_id: the camera's frame.
  const std::string& frame_id() const { return frame_id_; }

 private:
  void check_size(int w, int h, const std::string& enc, const std::string& what);
  std::int64_t stamp_or_log_time(std::int64_t stamp, const Message& m);
  std::size_t unstamped_ = 0;
  std::filesystem::path dir_;
  Serialization serialization_;
  bool compressed_;
  int width_ = 0, height_ = 0;
  std::string encoding_;
  std::string frame_id_;
  PixelFormat pixel_;
};

}  // namespace omnivert::recording
