#pragma once
// Checks of the descriptor's invariances (Sec. 3.1, 3.3) on real or drawn images: the image
// is rotated about its mirror centre or re-lit, features are extracted again, and each line
// of the original is paired with the line at its expected image angle. Used by the tests and
// by the study that picked the descriptor defaults (bench/describe/descriptor_choice.cpp).

#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/describe/frame_features.hpp"

namespace omnivert::eval {

// Rotates `image` about `center` so that image angles change by +angle_rad (bilinear).
cv::Mat rotate_about(const cv::Mat& image, const Eigen::Vector2d& center, double angle_rad);

// The pixels of rotate_about's copy that come wholly from inside `usable` (CV_8U, non-zero =
// usable; empty: every pixel of an image of `size`): 255 there, 0 where the copy's bilinear
// sample reads the zero fill beyond the original's frame or a masked pixel. The copy's corners
// are not image content: given as the copy's mask, they neither hide nor fake the rim.
cv::Mat rotated_usable(const cv::Mat& usable,
                       cv::Size size,
                       const Eigen::Vector2d& center,
                       double angle_rad);

// out = 255 * (gain * in / 255)^gamma, saturated.
cv::Mat relight(const cv::Mat& image, double gain, double gamma);

struct LinePairing {
  int original = -1;               // index into the original frame's lines
  int transformed = -1;            // index into the transformed frame's lines
  double angle_error = 0;          // wrapped (transformed - original - expected shift), rad
  double descriptor_distance = 0;  // Euclidean, eq. (6)
  // Is the transformed line's nearest descriptor among all original lines its own?
  bool nearest_is_correct = false;
  // Distance to the nearest original line other than the correct one (infinite if none).
  double nearest_wrong_distance = 0;
};

// The largest r_max for which the descriptor's support (the outer area plus its 3-sigma blur,
// sigma_G = r_a/3, r_a = (r_max - r_min)/6) stays inside the disc about `center` that fits in
// the image: with it, a rotation about the centre brings no new content into any descriptor.
double rotation_safe_r_max(const Eigen::Vector2d& center, int width, int height, double r_min);

// Pairs lines of two frames whose image angles agree within `tolerance_rad` after removing
// `shift_rad`, and of the same polarity. One pairing per original line at most.
std::vector<LinePairing> pair_lines(const FrameFeatures& original,
                                    const FrameFeatures& transformed,
                                    double shift_rad,
                                    double tolerance_rad);

}  // namespace omnivert::eval
