#include "omnivert/image/image_io.hpp"

#include <filesystem>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "omnivert/core/error.hpp"

namespace omnivert {

namespace fs = std::filesystem;

cv::Mat read_image(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path, 0, "file not found");
  if (fs::is_directory(path, ec))
    throw InputError(path, 0, "is a directory, expected an image file");
  if (const std::string why = unreadable_file_reason(path); !why.empty()) {
    throw InputError(path, 0, why);
  }
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, 0, "cannot be opened for reading (permissions?)");
  }
  cv::Mat img;
  try {
    img = cv::imread(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw InputError(path, 0, std::string("not a readable image: ") + e.what());
  }
  if (img.empty()) {
    throw InputError(path, 0, "not a readable image (expected PNG, JPEG, TIFF, PGM or BMP)");
  }
  return img;
}

namespace {

fs::path temp_sibling(const fs::path& p) {
  // Keep the extension last: OpenCV picks the format from it.
  return p.parent_path() / (".tmp-" + p.stem().string() + p.extension().string());
}

}  // namespace

void write_image_atomic(const std::string& path, const cv::Mat& image) {
  const fs::path p(path);
  if (!cv::haveImageWriter(path)) {
    throw InputError(path, 0, "unsupported image extension (use .png, .jpg, .tiff, .pgm or .bmp)");
  }
  const fs::path tmp = temp_sibling(p);
  bool ok = false;
  try {
    ok = cv::imwrite(tmp.string(), image);
  } catch (const cv::Exception&) {
    ok = false;
  }
  std::error_code ec;
  if (!ok) {
    fs::remove(tmp, ec);
    throw InputError(path, 0, "cannot write the image (does the folder exist and is it writable?)");
  }
  fs::rename(tmp, p, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(path, 0, "cannot write the image: " + ec.message());
  }
}

}  // namespace omnivert
