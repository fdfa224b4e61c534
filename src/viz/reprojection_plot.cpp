#include "omnivert/viz/reprojection_plot.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace omnivert::viz {

namespace {

cv::Point2d at(const MirrorCircle& c, int sign, double bearing, double r) {
  const double a = sign * bearing;  // image angle of a bearing (conventions)
  return {c.center.x() + r * std::cos(a), c.center.y() + r * std::sin(a)};
}

// Radius of a point at distance d: a polar plot of the reference over the annulus.
double radius_of(const MirrorCircle& c, double d) {
  return c.r_min + (c.r_max - c.r_min) * d / (d + 1.5);
}

}  // namespace

cv::Mat draw_reprojection(const cv::Mat& image,
                          const MirrorCircle& c,
                          int sign,
                          const std::vector<double>& lines,
                          const ReprojectionLayer& layer) {
  cv::Mat out;
  if (image.channels() == 1)
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  else
    out = image.clone();
  const int shift = 4;
  const double s = 1 << shift;
  auto fixed = [&](const cv::Point2d& p) {
    return cv::Point(static_cast<int>(std::lround(p.x * s)),
                     static_cast<int>(std::lround(p.y * s)));
  };
  const cv::Scalar cyan(255, 255, 0), green(0, 230, 0), red(0, 0, 255), orange(0, 140, 255);
  for (const double b : lines)
    cv::line(out,
             fixed(at(c, sign, b, c.r_min)),
             fixed(at(c, sign, b, c.r_max)),
             cyan,
             1,
             cv::LINE_AA,
             shift);
  for (const Eigen::Vector2d& p : layer.points)
    cv::circle(out,
               fixed(at(c, sign, p.x(), radius_of(c, p.y()))),
               static_cast<int>(1.5 * s),
               green,
               cv::FILLED,
               cv::LINE_AA,
               shift);
  const double tick = 0.18 * (c.r_max - c.r_min);
  auto mark = [&](const Eigen::Vector2d& p, const cv::Scalar& col, int width) {
    cv::line(out,
             fixed(at(c, sign, p.x(), c.r_max + 2)),
             fixed(at(c, sign, p.x(), c.r_max + tick)),
             col,
             width,
             cv::LINE_AA,
             shift);
    cv::line(out,
             fixed(at(c, sign, p.x(), std::max(2.0, c.r_min - tick))),
             fixed(at(c, sign, p.x(), c.r_min - 2)),
             col,
             width,
             cv::LINE_AA,
             shift);
    cv::circle(out,
               fixed(at(c, sign, p.x(), radius_of(c, p.y()))),
               static_cast<int>(3 * s),
               col,
               1,
               cv::LINE_AA,
               shift);
  };
  for (std::size_t i = 0; i < layer.ends.size(); ++i)
    mark(layer.ends[i], i < layer.ends_matched.size() && !layer.ends_matched[i] ? orange : red, 1);
  for (std::size_t i = 0; i < layer.corners.size(); ++i)
    mark(layer.corners[i], i < layer.matched.size() && !layer.matched[i] ? orange : red, 2);
  // The title, one line per '\n'.
  std::vector<std::string> rows{""};
  for (const char ch : layer.title) {
    if (ch == '\n')
      rows.emplace_back();
    else
      rows.back() += ch;
  }
  cv::rectangle(out,
                cv::Rect(0, 0, out.cols, 4 + 18 * static_cast<int>(rows.size())),
                cv::Scalar(0, 0, 0),
                cv::FILLED);
  for (std::size_t i = 0; i < rows.size(); ++i)
    cv::putText(out,
                rows[i],
                cv::Point(6, 16 + 18 * static_cast<int>(i)),
                cv::FONT_HERSHEY_SIMPLEX,
                0.45,
                cv::Scalar(255, 255, 255),
                1,
                cv::LINE_AA);
  return out;
}

namespace {

cv::Mat concat(const std::vector<cv::Mat>& pictures, bool horizontal) {
  if (pictures.empty()) return {};
  int w = 0, h = 0;
  for (const cv::Mat& p : pictures) {
    w = horizontal ? w + p.cols : std::max(w, p.cols);
    h = horizontal ? std::max(h, p.rows) : h + p.rows;
  }
  cv::Mat out(h, w, CV_8UC3, cv::Scalar(0, 0, 0));
  int at = 0;
  for (const cv::Mat& p : pictures) {
    cv::Mat bgr;
    if (p.channels() == 1)
      cv::cvtColor(p, bgr, cv::COLOR_GRAY2BGR);
    else
      bgr = p;
    bgr.copyTo(out(horizontal ? cv::Rect(at, 0, p.cols, p.rows) : cv::Rect(0, at, p.cols, p.rows)));
    at += horizontal ? p.cols : p.rows;
  }
  return out;
}

}  // namespace

cv::Mat hconcat_pictures(const std::vector<cv::Mat>& pictures) { return concat(pictures, true); }
cv::Mat vconcat_pictures(const std::vector<cv::Mat>& pictures) { return concat(pictures, false); }

}  // namespace omnivert::viz
