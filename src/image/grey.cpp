#include "omnivert/image/grey.hpp"

#include <opencv2/imgproc.hpp>

namespace omnivert {

namespace {

bool fail(std::string* why, const std::string& reason) {
  if (why) *why = reason;
  return false;
}

// OpenCV names a Bayer conversion by the second and third pixels of its second row, one
// pixel right and one down of the top-left 2x2 block that the usual names (and
// sensor.yaml) give: RGGB is OpenCV's BG, and so on.
int demosaic_code(BayerPattern p) {
  switch (p) {
    case BayerPattern::kRGGB:
      return cv::COLOR_BayerBG2GRAY;
    case BayerPattern::kBGGR:
      return cv::COLOR_BayerRG2GRAY;
    case BayerPattern::kGRBG:
      return cv::COLOR_BayerGB2GRAY;
    case BayerPattern::kGBRG:
      return cv::COLOR_BayerGR2GRAY;
    case BayerPattern::kNone:
      break;
  }
  return -1;
}

std::string depth_name(int depth) {
  switch (depth) {
    case CV_8S:
      return "8-bit signed";
    case CV_16S:
      return "16-bit signed";
    case CV_32S:
      return "32-bit integer";
    case CV_16F:
      return "16-bit floating-point";
    default:
      return "unsupported";
  }
}

}  // namespace

bool to_grey8(const cv::Mat& image, const PixelFormat& format, cv::Mat& grey, std::string* why) {
  if (why) why->clear();
  if (image.empty() || image.dims != 2) return fail(why, "empty image");
  const int depth = image.depth();
  if (depth != CV_8U && depth != CV_16U && depth != CV_32F && depth != CV_64F) {
    return fail(why,
                depth_name(depth) +
                    " pixels are not supported (expected 8- or 16-bit unsigned, or "
                    "floating point in 0..1)");
  }
  if (format.bit_depth != 0 && depth != CV_16U) {
    return fail(why,
                "the camera's bit_depth is " + std::to_string(format.bit_depth) +
                    " but the image is not 16 bits deep; remove bit_depth from sensor.yaml");
  }
  cv::Mat g;
  if (format.bayer != BayerPattern::kNone) {
    if (image.channels() != 1) {
      return fail(why,
                  std::string("the camera's images are Bayer mosaics (bayer: ") +
                      bayer_pattern_name(format.bayer) + ") but this image has " +
                      std::to_string(image.channels()) +
                      " channels; set bayer: none in sensor.yaml for colour images");
    }
    if (depth != CV_8U && depth != CV_16U) {
      return fail(why, "a Bayer mosaic must have 8- or 16-bit pixels");
    }
    if (image.cols < 4 || image.rows < 4) return fail(why, "a Bayer mosaic of under 4x4 pixels");
    cv::cvtColor(image, g, demosaic_code(format.bayer));
  } else {
    switch (image.channels()) {
      case 1:
        g = image;
        break;
      case 3:
        cv::cvtColor(image, g, cv::COLOR_BGR2GRAY);
        break;
      case 4:
        cv::cvtColor(image, g, cv::COLOR_BGRA2GRAY);
        break;
      default:
        return fail(why,
                    "an image with " + std::to_string(image.channels()) +
                        " channels (expected grey, colour or colour with alpha)");
    }
  }
  switch (depth) {
    case CV_8U:
      grey = g.isContinuous() ? g : g.clone();
      return true;
    case CV_16U: {
      const int bits = format.bit_depth ? format.bit_depth : 16;
      g.convertTo(grey, CV_8U, 255.0 / ((1 << bits) - 1));
      return true;
    }
    default:  // CV_32F, CV_64F
      g.convertTo(grey, CV_8U, 255.0);
      return true;
  }
}

}  // namespace omnivert
