#include "omnivert/eval/panorama.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"

namespace omnivert::eval {

double Panorama::column_of_bearing(double bearing) const {
  return wrap_positive(bearing) / kTwoPi * width();
}

double Panorama::bearing_of_column(double column) const {
  return wrap_angle(column * kTwoPi / width());
}

double Panorama::radius_of_row(double row) const {
  const double step = rows() > 1 ? (circle.r_max - circle.r_min) / (rows() - 1) : 0.0;
  return circle.r_max - row * step;
}

double Panorama::arc_per_column(double r) const { return kTwoPi * r / width(); }

Panorama unwrap_panorama(const cv::Mat& image,
                         const MirrorCircle& circle,
                         const PanoramaOptions& options) {
  if (image.empty()) throw std::invalid_argument("unwrap_panorama: empty image");
  if (!(circle.r_min >= 0.0 && circle.r_min < circle.r_max))
    throw std::invalid_argument("unwrap_panorama: need 0 <= r_min < r_max");
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  } else {
    grey = image;
  }
  cv::Mat1f src;
  grey.convertTo(src, CV_32F);

  Panorama p;
  p.circle = circle;
  p.bearing_sign = options.bearing_sign >= 0 ? 1 : -1;
  int width = options.width;
  if (width <= 0) {
    const double circumference = kPi * (circle.r_min + circle.r_max);
    width = 360 * std::max(1, static_cast<int>(std::lround(circumference / 360.0)));
  }
  const int rows = options.rows > 0
                       ? options.rows
                       : static_cast<int>(std::lround(circle.r_max - circle.r_min)) + 1;
  p.image.create(rows, width);
  cv::Mat1f map_x(rows, width), map_y(rows, width);
  std::vector<double> cs(width), sn(width);
  for (int c = 0; c < width; ++c) {
    const double a = p.bearing_sign * (c * kTwoPi / width);
    cs[c] = std::cos(a);
    sn[c] = std::sin(a);
  }
  for (int i = 0; i < rows; ++i) {
    const double r = p.radius_of_row(i);
    float* mx = map_x[i];
    float* my = map_y[i];
    for (int c = 0; c < width; ++c) {
      mx[c] = static_cast<float>(circle.center.x() + r * cs[c]);
      my[c] = static_cast<float>(circle.center.y() + r * sn[c]);
    }
  }
  cv::remap(src, p.image, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  return p;
}

cv::Mat1f panorama_pattern(const Panorama& panorama, double bearing, int width_columns) {
  width_columns = std::max(1, width_columns);
  const int w = panorama.width();
  const double c0 = panorama.column_of_bearing(bearing) - 0.5 * (width_columns - 1);
  cv::Mat1f out(panorama.rows(), width_columns);
  for (int k = 0; k < width_columns; ++k) {
    const double c = c0 + k;
    const double fl = std::floor(c);
    const double t = c - fl;
    int a = static_cast<int>(fl) % w;
    if (a < 0) a += w;
    const int b = (a + 1) % w;
    for (int i = 0; i < panorama.rows(); ++i) {
      const float* row = panorama.image[i];
      out(i, k) = static_cast<float>((1.0 - t) * row[a] + t * row[b]);
    }
  }
  return out;
}

int paper_pattern_columns(const Panorama& panorama) {
  const double r_a = (panorama.circle.r_max - panorama.circle.r_min) / 6.0;
  const double r_mid = 0.5 * (panorama.circle.r_min + panorama.circle.r_max);
  return std::max(1, static_cast<int>(std::lround(2.0 * r_a / panorama.arc_per_column(r_mid))));
}

double ssd_per_pixel(const cv::Mat1f& a, const cv::Mat1f& b) {
  CV_Assert(a.size() == b.size() && !a.empty());
  double s = 0.0;
  for (int i = 0; i < a.rows; ++i) {
    const float* pa = a[i];
    const float* pb = b[i];
    for (int j = 0; j < a.cols; ++j) {
      const double d = static_cast<double>(pa[j]) - pb[j];
      s += d * d;
    }
  }
  return s / static_cast<double>(a.total());
}

double zncc(const cv::Mat1f& a, const cv::Mat1f& b) {
  CV_Assert(a.size() == b.size() && !a.empty());
  const double n = static_cast<double>(a.total());
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (int i = 0; i < a.rows; ++i) {
    const float* pa = a[i];
    const float* pb = b[i];
    for (int j = 0; j < a.cols; ++j) {
      const double x = pa[j], y = pb[j];
      sa += x, sb += y, saa += x * x, sbb += y * y, sab += x * y;
    }
  }
  const double va = saa - sa * sa / n;
  const double vb = sbb - sb * sb / n;
  const double eps = 1e-9 * n;
  if (va <= eps || vb <= eps) return 0.0;
  return std::clamp((sab - sa * sb / n) / std::sqrt(va * vb), -1.0, 1.0);
}

}  // namespace omnivert::eval
