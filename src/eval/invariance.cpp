#include "omnivert/eval/invariance.hpp"

#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"

namespace omnivert::eval {

cv::Mat rotate_about(const cv::Mat& image, const Eigen::Vector2d& center, double angle_rad) {
  // getRotationMatrix2D(+t) maps an offset at image angle a to a - t (v points down), so
  // rotate by -angle to add +angle to every image angle.
  const cv::Mat M = cv::getRotationMatrix2D(
      cv::Point2f(static_cast<float>(center.x()), static_cast<float>(center.y())),
      -rad2deg(angle_rad),
      1.0);
  cv::Mat out;
  cv::warpAffine(image, out, M, image.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  return out;
}

cv::Mat rotated_usable(const cv::Mat& usable,
                       cv::Size size,
                       const Eigen::Vector2d& center,
                       double angle_rad) {
  cv::Mat ones = usable.empty() ? cv::Mat(size, CV_8U, cv::Scalar(255)) : (usable != 0);
  cv::Mat out = rotate_about(ones, center, angle_rad);
  return out == 255;  // every bilinear neighbour usable
}

cv::Mat relight(const cv::Mat& image, double gain, double gamma) {
  cv::Mat lut(1, 256, CV_8U);
  for (int i = 0; i < 256; ++i) {
    const double v = 255.0 * std::pow(std::min(1.0, gain * i / 255.0), gamma);
    lut.at<uchar>(i) = cv::saturate_cast<uchar>(v);
  }
  cv::Mat out;
  cv::LUT(image, lut, out);
  return out;
}

double rotation_safe_r_max(const Eigen::Vector2d& c, int width, int height, double r_min) {
  const double inscribed = std::min({c.x(), c.y(), width - 1 - c.x(), height - 1 - c.y()});
  // r_max + 3 sigma_G = r_max + (r_max - r_min) / 6 <= inscribed - 2
  return (inscribed - 2 + r_min / 6.0) / (7.0 / 6.0);
}

std::vector<LinePairing> pair_lines(const FrameFeatures& a,
                                    const FrameFeatures& b,
                                    double shift_rad,
                                    double tolerance_rad) {
  std::vector<LinePairing> out;
  for (int i = 0; i < static_cast<int>(a.lines.size()); ++i) {
    int best = -1;
    double best_err = tolerance_rad;
    for (int j = 0; j < static_cast<int>(b.lines.size()); ++j) {
      if (a.lines[i].polarity != b.lines[j].polarity) continue;
      const double e =
          std::abs(angle_diff(b.lines[j].image_angle, a.lines[i].image_angle + shift_rad));
      if (e <= best_err) best_err = e, best = j;
    }
    if (best < 0) continue;
    LinePairing p;
    p.original = i;
    p.transformed = best;
    p.angle_error = angle_diff(b.lines[best].image_angle, a.lines[i].image_angle + shift_rad);
    p.descriptor_distance = (a.descriptors.row(i) - b.descriptors.row(best)).norm();
    double wrong = std::numeric_limits<double>::infinity();
    for (int k = 0; k < static_cast<int>(a.lines.size()); ++k) {
      if (k == i) continue;
      wrong = std::min(
          wrong, static_cast<double>((a.descriptors.row(k) - b.descriptors.row(best)).norm()));
    }
    p.nearest_wrong_distance = wrong;
    p.nearest_is_correct = p.descriptor_distance < wrong;
    out.push_back(p);
  }
  return out;
}

}  // namespace omnivert::eval
