#include "omnivert/viz/overlay.hpp"

#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "omnivert/describe/feature_pipeline.hpp"

namespace omnivert::viz {

cv::Mat draw_overlay(const cv::Mat& image,
                     const FrameFeatures& f,
                     const DescriptorExtractor& descriptor,
                     int highlight) {
  cv::Mat gray, bgr;
  FeaturePipeline::to_gray8(image, gray);
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  const double scale = std::max(1.0, std::max(bgr.cols, bgr.rows) / 800.0);
  const int thick = static_cast<int>(std::lround(scale));
  const int shift = 4;  // sub-pixel drawing
  auto P = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround(x * 16)), static_cast<int>(std::lround(y * 16)));
  };
  const auto& c = f.circle;
  cv::circle(bgr,
             P(c.center.x(), c.center.y()),
             static_cast<int>(c.r_min * 16),
             {255, 160, 0},
             thick,
             cv::LINE_AA,
             shift);
  cv::circle(bgr,
             P(c.center.x(), c.center.y()),
             static_cast<int>(c.r_max * 16),
             {255, 160, 0},
             thick,
             cv::LINE_AA,
             shift);
  if (c.rim_radius > 0)
    cv::circle(bgr,
               P(c.center.x(), c.center.y()),
               static_cast<int>(c.rim_radius * 16),
               {0, 200, 255},
               thick,
               cv::LINE_AA,
               shift);
  const double m = 6 * scale;
  cv::line(bgr,
           P(c.center.x() - m, c.center.y()),
           P(c.center.x() + m, c.center.y()),
           {0, 0, 255},
           thick,
           cv::LINE_AA,
           shift);
  cv::line(bgr,
           P(c.center.x(), c.center.y() - m),
           P(c.center.x(), c.center.y() + m),
           {0, 0, 255},
           thick,
           cv::LINE_AA,
           shift);

  if (highlight < 0 && !f.lines.empty()) {
    highlight = 0;
    for (std::size_t i = 1; i < f.lines.size(); ++i)
      if (f.lines[i].edge_pixels > f.lines[highlight].edge_pixels) highlight = static_cast<int>(i);
  }
  for (std::size_t i = 0; i < f.lines.size(); ++i) {
    const auto& l = f.lines[i];
    const double ca = std::cos(l.image_angle), sa = std::sin(l.image_angle);
    const cv::Scalar col = l.polarity > 0 ? cv::Scalar(0, 255, 0) : cv::Scalar(255, 0, 255);
    cv::line(bgr,
             P(c.center.x() + l.r_inner * ca, c.center.y() + l.r_inner * sa),
             P(c.center.x() + l.r_outer * ca, c.center.y() + l.r_outer * sa),
             col,
             thick + 1,
             cv::LINE_AA,
             shift);
    const double rt = c.r_max + 10 * scale;
    cv::putText(bgr,
                std::to_string(i),
                cv::Point(static_cast<int>(c.center.x() + rt * ca - 6 * scale),
                          static_cast<int>(c.center.y() + rt * sa + 4 * scale)),
                cv::FONT_HERSHEY_SIMPLEX,
                0.4 * scale,
                l.crowded ? cv::Scalar(0, 0, 255) : cv::Scalar(0, 255, 255),
                thick,
                cv::LINE_AA);
  }
  if (highlight >= 0 && highlight < static_cast<int>(f.lines.size())) {
    const double ra = descriptor.area_radius(c);
    for (const auto& p : descriptor.area_centers(c, f.lines[highlight].image_angle))
      cv::circle(
          bgr, P(p.x, p.y), static_cast<int>(ra * 16), {0, 128, 255}, thick, cv::LINE_AA, shift);
  }
  return bgr;
}

cv::Mat draw_camera_overlay(const cv::Mat& image, const CameraEstimate& e) {
  cv::Mat gray, bgr;
  FeaturePipeline::to_gray8(image, gray);
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  const auto& c = e.circle;
  if (!e.mask.empty() && e.mask.size() == bgr.size()) {
    cv::Mat annulus = cv::Mat::zeros(bgr.size(), CV_8U);
    const cv::Point ci(static_cast<int>(std::lround(c.center.x())),
                       static_cast<int>(std::lround(c.center.y())));
    cv::circle(annulus, ci, static_cast<int>(c.r_max), 255, cv::FILLED);
    cv::circle(annulus, ci, static_cast<int>(c.r_min), 0, cv::FILLED);
    cv::Mat tinted;
    cv::addWeighted(bgr, 0.5, cv::Mat(bgr.size(), CV_8UC3, cv::Scalar(0, 0, 255)), 0.5, 0, tinted);
    tinted.copyTo(bgr, annulus & (e.mask == 0));
  }
  const int thick =
      static_cast<int>(std::lround(std::max(1.0, std::max(bgr.cols, bgr.rows) / 800.0)));
  const int shift = 4;
  auto P = [](const Eigen::Vector2d& p) {
    return cv::Point(static_cast<int>(std::lround(p.x() * 16)),
                     static_cast<int>(std::lround(p.y() * 16)));
  };
  auto ring = [&](double r, const cv::Scalar& col) {
    if (r > 0)
      cv::circle(bgr, P(c.center), static_cast<int>(r * 16), col, thick, cv::LINE_AA, shift);
  };
  ring(c.r_min, {255, 160, 0});
  ring(c.r_max, {255, 160, 0});
  ring(c.rim_radius, {0, 220, 255});
  for (const auto& f : e.frames) {
    if (!f.found) continue;
    const Eigen::Vector2d p = c.center + 10.0 * (f.circle.center - c.center);
    cv::circle(bgr,
               P(p),
               3 * 16 * thick,
               f.inlier ? cv::Scalar(0, 200, 0) : cv::Scalar(255, 0, 255),
               cv::FILLED,
               cv::LINE_AA,
               shift);
  }
  const double m = 10.0 * thick;
  cv::line(bgr,
           P(c.center - Eigen::Vector2d(m, 0)),
           P(c.center + Eigen::Vector2d(m, 0)),
           {0, 0, 255},
           thick,
           cv::LINE_AA,
           shift);
  cv::line(bgr,
           P(c.center - Eigen::Vector2d(0, m)),
           P(c.center + Eigen::Vector2d(0, m)),
           {0, 0, 255},
           thick,
           cv::LINE_AA,
           shift);
  return bgr;
}

}  // namespace omnivert::viz
