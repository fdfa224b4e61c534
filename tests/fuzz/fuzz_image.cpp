// libFuzzer harness of the image path: an image file read as stored (read_image, OpenCV's
// decoders) and turned into the 8-bit grey image every stage works on (to_grey8) with each
// pixel format a cam0/sensor.yaml can give.

#include <cstdint>
#include <cstdlib>
#include <string>

#include "fuzz_support.hpp"
#include "omnivert/image/grey.hpp"
#include "omnivert/image/image_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  // The first byte chooses the pixel format (Bayer pattern, bit depth); the rest is the file.
  omnivert::PixelFormat format;
  format.bayer = static_cast<omnivert::BayerPattern>(data[0] % 5);
  const int depths[] = {0, 9, 12, 16};
  format.bit_depth = depths[(data[0] / 5) % 4];
  const auto path = (omnivert::fuzz::scratch() / "image").string();
  omnivert::fuzz::write_file(path, omnivert::fuzz::as_text(data + 1, size - 1));
  omnivert::fuzz::expect_input_error_or_success([&] {
    const cv::Mat raw = omnivert::read_image(path);
    cv::Mat grey;
    std::string why;
    if (omnivert::to_grey8(raw, format, grey, &why)) {
      if (grey.type() != CV_8UC1 || grey.size() != raw.size()) std::abort();
    } else if (why.empty()) {
      std::abort();
    }
  });
  return 0;
}
