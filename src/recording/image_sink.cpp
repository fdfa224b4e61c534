#include "recording/image_sink.hpp"

#include <cstring>
#include <fstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "omnivert/core/error.hpp"
#include "omnivert/recording/messages.hpp"

namespace omnivert::recording {

namespace {

const char* kEncodings =
    "mono8, mono16, 8UC1, 16UC1, rgb8, bgr8, rgba8, bgra8, bayer_rggb8, bayer_bggr8, bayer_gbrg8, "
    "bayer_grbg8 and their 16-bit forms";

constexpr std::uint32_t kMaxSide = 1 << 20;

struct Layout {
  int cv_type = 0;
  int conversion = -1;  // cv::cvtColor code to BGR, or -1
  BayerPattern bayer = BayerPattern::kNone;
};

bool layout_of(const std::string& e, Layout& l) {
  if (e == "mono8" || e == "8UC1")
    l = {CV_8UC1};
  else if (e == "mono16" || e == "16UC1")
    l = {CV_16UC1};
  else if (e == "bgr8" || e == "8UC3")
    l = {CV_8UC3};
  else if (e == "rgb8")
    l = {CV_8UC3, cv::COLOR_RGB2BGR};
  else if (e == "rgba8")
    l = {CV_8UC4, cv::COLOR_RGBA2BGR};
  else if (e == "bgra8" || e == "8UC4")
    l = {CV_8UC4, cv::COLOR_BGRA2BGR};
  else if (e.rfind("bayer_", 0) == 0 && (e.size() == 11 || e.size() == 12)) {
    const auto p = parse_bayer_pattern(e.substr(6, 4));
    const std::string bits = e.substr(10);
    if (!p || (bits != "8" && bits != "16")) return false;
    l = {bits == "8" ? CV_8UC1 : CV_16UC1, -1, *p};
  } else {
    return false;
  }
  return true;
}

void write_bytes(const std::filesystem::path& p, std::span<const std::uint8_t> data) {
  std::ofstream out(p, std::ios::binary);
  out.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
  if (!out)
    throw InputError(p.string(), 0, "cannot write (disk full, or a folder that is not writable?)");
}

}  // namespace

std::int64_t ImageSink::stamp_or_log_time(std::int64_t stamp, const Message& m) {
  if (stamp != 0) return stamp;
  ++unstamped_;
  return m.log_time_ns;
}

void ImageSink::check_size(int w, int h, const std::string& enc, const std::string& what) {
  if (width_ == 0) {
    width_ = w;
    height_ = h;
    encoding_ = enc;
    return;
  }
  if (w != width_ || h != height_ || enc != encoding_) {
    throw InputError(what + ": a " + std::to_string(w) + "x" + std::to_string(h) + " " + enc +
                     " image after " + std::to_string(width_) + "x" + std::to_string(height_) +
                     " " + encoding_ +
                     " ones; the images of a dataset share one size and encoding");
  }
}

std::int64_t ImageSink::add(const Message& m, const std::string& what, std::string& filename) {
  if (compressed_) {
    const CompressedImageMsg c = decode_compressed_image(m.data, serialization_, what);
    if (width_ == 0) frame_id_ = c.frame_id;
    const auto& d = c.data;
    std::string kind;
    if (d.size() >= 8 && std::memcmp(d.data(), "\x89PNG\r\n\x1a\n", 8) == 0)
      kind = "png";
    else if (d.size() >= 3 && d[0] == 0xFF && d[1] == 0xD8 && d[2] == 0xFF)
      kind = "jpeg";
    else {
      throw InputError(what + ": compressed image format '" + c.format +
                       "' is not one we read (jpeg, png)");
    }
    if (width_ == 0) {
      const cv::Mat img = cv::imdecode(
          cv::Mat(1, static_cast<int>(d.size()), CV_8UC1, const_cast<std::uint8_t*>(d.data())),
          cv::IMREAD_UNCHANGED);
      if (img.empty()) throw InputError(what + ": the " + kind + " image does not decode");
      check_size(img.cols, img.rows, kind, what);
      if (img.depth() == CV_16U) pixel_.bit_depth = 0;
    } else {
      check_size(width_, height_, kind, what);
    }
    const std::int64_t t = stamp_or_log_time(c.stamp_ns, m);
    filename = std::to_string(t) + (kind == "png" ? ".png" : ".jpg");
    write_bytes(dir_ / filename, d);
    return t;
  }
  const ImageMsg im = decode_image(m.data, serialization_, what);
  if (width_ == 0) frame_id_ = im.frame_id;
  Layout l;
  if (!layout_of(im.encoding, l)) {
    throw InputError(what + ": image encoding '" + im.encoding + "' is not one we read (" +
                     kEncodings + ")");
  }
  // Before the sizes become an int and a cv::Mat: an empty image, or one wider or taller
  // than any camera's, is refused.
  if (im.width == 0 || im.height == 0)
    throw InputError(what + ": an empty image (width or height 0)");
  if (im.width > kMaxSide || im.height > kMaxSide) {
    throw InputError(what + ": a " + std::to_string(im.width) + "x" + std::to_string(im.height) +
                     " image (more than " + std::to_string(kMaxSide) + " pixels a side)");
  }
  check_size(static_cast<int>(im.width), static_cast<int>(im.height), im.encoding, what);
  const std::size_t row = static_cast<std::size_t>(im.width) * CV_ELEM_SIZE(l.cv_type);
  if (im.step < row || im.data.size() < static_cast<std::size_t>(im.step) * im.height) {
    throw InputError(what + ": " + std::to_string(im.data.size()) + " bytes of data for a " +
                     std::to_string(im.width) + "x" + std::to_string(im.height) + " " +
                     im.encoding + " image with step " + std::to_string(im.step));
  }
  cv::Mat img(static_cast<int>(im.height),
              static_cast<int>(im.width),
              l.cv_type,
              const_cast<std::uint8_t*>(im.data.data()),
              im.step);
  cv::Mat out = img;
  if (CV_MAT_DEPTH(l.cv_type) == CV_16U && im.big_endian) {
    out = img.clone();
    for (int y = 0; y < out.rows; ++y) {
      auto* p = out.ptr<std::uint16_t>(y);
      for (int x = 0; x < out.cols; ++x)
        p[x] = static_cast<std::uint16_t>((p[x] >> 8) | (p[x] << 8));
    }
  }
  if (l.conversion >= 0) cv::cvtColor(img, out, l.conversion);
  pixel_.bayer = l.bayer;
  const std::int64_t t = stamp_or_log_time(im.stamp_ns, m);
  filename = std::to_string(t) + ".png";
  const std::vector<int> params = {cv::IMWRITE_PNG_COMPRESSION, 3};
  if (!cv::imwrite((dir_ / filename).string(), out, params)) {
    throw InputError((dir_ / filename).string(),
                     0,
                     "cannot write (disk full, or a folder that is not writable?)");
  }
  return t;
}

}  // namespace omnivert::recording
