#pragma once
// Image masks: which pixels of a camera's images show the scene (docs/dataset-format.md,
// `mask:`). A mask file is a one-channel image (8- or 16-bit grey PNG, or any file OpenCV
// reads as one channel) of the camera's resolution; a non-zero pixel is usable, zero is not
// (the robot's own reflection, mount struts, cables). Colour images are refused: a mask's
// meaning must not depend on a conversion to grey.

#include <string>

#include <opencv2/core.hpp>

namespace omnivert {

// Reads a mask file as CV_8UC1, 255 = usable, 0 = masked. width/height > 0: the size the
// mask must have. Throws InputError naming the file for: a missing or unreadable file, more
// than one channel, a wrong size (both sizes in the message), no usable pixel.
cv::Mat read_mask(const std::string& path, int width = 0, int height = 0);

// The usable area shrunk by `radius` pixels (a pixel stays usable when every pixel of the
// (2 radius + 1)^2 square around it is): a stage whose kernel reaches `radius` pixels
// ignores the pixels whose kernel touches the mask. Pixels beyond the image border count
// as usable (the stages skip the border themselves). An empty mask gives an empty result.
cv::Mat erode_mask(const cv::Mat& usable, int radius);

// True when every pixel of the mask is usable (the stages then take their unmasked path,
// with bit-identical results).
bool mask_all_usable(const cv::Mat& usable);

}  // namespace omnivert
