#pragma once
// The 8-bit grey image every stage works on, from an image as it is stored: grey or colour,
// 8 or 16 bits (or floating point in 0..1), or a raw Bayer mosaic
// (docs/dataset-format.md#pixel-format).

#include <string>

#include <opencv2/core.hpp>

#include "omnivert/core/camera_geometry.hpp"

namespace omnivert {

// Converts `image` to 8-bit grey into `grey`:
//  - colour (3 channels BGR, as image files are read; 4 channels BGRA): luma
//    Y = 0.299 R + 0.587 G + 0.114 B (ITU-R BT.601, the weights of a JPEG's own grey);
//  - a single channel with format.bayer set: demosaiced (bilinear) to grey first;
//  - 16 bits: scaled by 255 / (2^bits - 1), bits = format.bit_depth or 16, rounded and
//    saturated; floating point: 0..1 scaled to 0..255;
//  - 8-bit grey: as it is (no copy when continuous).
// Returns false with the reason in *why (when not null) for what cannot be converted: two
// channels, signed or 32-bit integer pixels, a Bayer pattern given for a colour image, a
// bit depth given for an 8-bit image.
bool to_grey8(const cv::Mat& image, const PixelFormat& format, cv::Mat& grey, std::string* why);

}  // namespace omnivert
