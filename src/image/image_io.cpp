#include "omnivert/image/image_io.hpp"

#include <filesystem>
#include <fstream>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "omnivert/core/error.hpp"

namespace omnivert {

namespace fs = std::filesystem;

namespace {

// The first bytes of the formats read_image accepts, each tested as strictly as OpenCV's own
// decoder tests it. cv::imread hands a file to the first decoder, in its fixed order, whose
// signature test passes; the decoders of these formats come before the ones that abort on a
// hostile file (GDCM's DICOM reader, which looks for "DICM" at byte 128). A file that one of
// these decoders claims never reaches those; a file that starts like PNM but that OpenCV's PNM
// decoder refuses ("P5" not followed by white space) would (fuzz_image found one).
bool has_image_signature(const std::string& h) {
  auto starts = [&h](const char* sig, std::size_t n) {
    return h.size() >= n && h.compare(0, n, sig, n) == 0;
  };
  if (starts("\x89PNG\r\n\x1a\n", 8)) return true;            // PNG
  if (starts("\xff\xd8\xff", 3)) return true;                 // JPEG
  if (starts("II*\0", 4) || starts("MM\0*", 4)) return true;  // TIFF
  if (starts("BM", 2)) return true;                           // BMP
  if (h.size() >= 3 && h[0] == 'P' && h[1] >= '1' && h[1] <= '6' &&
      (h[2] == ' ' || h[2] == '\n' || h[2] == '\r' || h[2] == '\t'))
    return true;  // PBM, PGM, PPM
  // Not WebP: OpenCV's WebP decoder claims a file only when libwebp parses its first 32 bytes,
  // a test this one cannot repeat; a "RIFF....WEBP" file it refuses would go on to the others.
  return false;
}

}  // namespace

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
    // Only the formats we read are handed to OpenCV: cv::imread tries every decoder it was
    // built with, and some abort the program on a hostile file (fuzz_image found a file
    // that makes GDCM's DICOM reader fail an assertion).
    char head[8] = {};
    in.read(head, sizeof(head));
    if (!has_image_signature(std::string(head, static_cast<std::size_t>(in.gcount())))) {
      throw InputError(path,
                       0,
                       "not a readable image (it does not start with the signature of PNG, "
                       "JPEG, TIFF, PGM/PPM or BMP)");
    }
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
