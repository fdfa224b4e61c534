#include "omnivert/image/image_mask.hpp"

#include <opencv2/imgproc.hpp>

#include "omnivert/core/error.hpp"
#include "omnivert/image/image_io.hpp"

namespace omnivert {

namespace {

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

}  // namespace

cv::Mat read_mask(const std::string& path, int width, int height) {
  const cv::Mat m = read_image(path);
  if (m.channels() != 1) {
    throw InputError(path,
                     0,
                     "a mask must be a one-channel (grey) image, this one has " +
                         std::to_string(m.channels()) +
                         " channels (save it as an 8-bit grey PNG: non-zero = usable pixel)");
  }
  if (width > 0 && (m.cols != width || m.rows != height)) {
    throw InputError(path,
                     0,
                     "mask is " + size_text(m.cols, m.rows) + " but the camera's resolution is " +
                         size_text(width, height));
  }
  cv::Mat usable;
  cv::compare(m, 0, usable, cv::CMP_NE);  // 255 where non-zero, whatever the depth
  if (cv::countNonZero(usable) == 0) {
    throw InputError(path, 0, "mask has no usable pixel (every pixel is zero; non-zero = usable)");
  }
  return usable;
}

cv::Mat erode_mask(const cv::Mat& usable, int radius) {
  if (usable.empty() || radius <= 0) return usable.clone();
  cv::Mat out;
  const cv::Mat kernel = cv::Mat::ones(2 * radius + 1, 2 * radius + 1, CV_8U);
  // The default border value of erode is the maximum: outside the image counts as usable.
  cv::erode(usable, out, kernel);
  return out;
}

bool mask_all_usable(const cv::Mat& usable) {
  return !usable.empty() && cv::countNonZero(usable) == static_cast<int>(usable.total());
}

}  // namespace omnivert
