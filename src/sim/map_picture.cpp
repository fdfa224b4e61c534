#include "omnivert/sim/map_picture.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace omnivert::sim {

cv::Mat3b draw_map(const World& world,
                   const std::vector<Pose2>& robot,
                   const std::vector<Eigen::Vector2d>& camera,
                   int max_size) {
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  auto grow = [&](const Eigen::Vector2d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  };
  for (const Wall& w : world.walls) {
    grow(w.from);
    grow(w.to);
  }
  for (const Pose2& p : robot) grow(p.head<2>());
  if (lo.x() > hi.x()) return cv::Mat3b(100, 100, cv::Vec3b(255, 255, 255));
  const double margin = 0.5;
  lo.array() -= margin;
  hi.array() += margin;
  const Eigen::Vector2d span = hi - lo;
  const double scale = (max_size - 1) / std::max(span.x(), span.y());
  cv::Mat3b img(static_cast<int>(span.y() * scale) + 1,
                static_cast<int>(span.x() * scale) + 1,
                cv::Vec3b(255, 255, 255));
  const int shift = 4;  // sub-pixel drawing
  auto px = [&](const Eigen::Vector2d& p) {
    return cv::Point(static_cast<int>(std::lround((p.x() - lo.x()) * scale * (1 << shift))),
                     static_cast<int>(std::lround((hi.y() - p.y()) * scale * (1 << shift))));
  };
  // 1 m grid.
  for (double x = std::ceil(lo.x()); x <= hi.x(); x += 1.0) {
    cv::line(
        img, px({x, lo.y()}), px({x, hi.y()}), cv::Scalar(235, 235, 235), 1, cv::LINE_AA, shift);
  }
  for (double y = std::ceil(lo.y()); y <= hi.y(); y += 1.0) {
    cv::line(
        img, px({lo.x(), y}), px({hi.x(), y}), cv::Scalar(235, 235, 235), 1, cv::LINE_AA, shift);
  }
  for (const Wall& w : world.walls) {
    const bool full = world.top(w) >= world.height && w.z0 <= 0.0;
    cv::line(img,
             px(w.from),
             px(w.to),
             full ? cv::Scalar(90, 90, 90) : cv::Scalar(170, 170, 170),
             2,
             cv::LINE_AA,
             shift);
  }
  for (const VerticalEdge& e : world.edges()) {
    const bool full = e.z0 <= 0.0 && e.z1 >= world.height;
    cv::circle(img,
               px(e.p),
               2 << shift,
               full ? cv::Scalar(40, 40, 40) : cv::Scalar(40, 40, 220),
               -1,
               cv::LINE_AA,
               shift);
  }
  for (std::size_t i = 1; i < camera.size(); ++i) {
    cv::line(img, px(camera[i - 1]), px(camera[i]), cv::Scalar(0, 140, 255), 1, cv::LINE_AA, shift);
  }
  for (std::size_t i = 1; i < robot.size(); ++i) {
    cv::line(img,
             px(robot[i - 1].head<2>()),
             px(robot[i].head<2>()),
             cv::Scalar(200, 80, 0),
             2,
             cv::LINE_AA,
             shift);
  }
  if (!robot.empty()) {
    const Pose2& s = robot.front();
    const Eigen::Vector2d tip =
        s.head<2>() + 0.4 * Eigen::Vector2d(std::cos(s.z()), std::sin(s.z()));
    cv::circle(img, px(s.head<2>()), 5 << shift, cv::Scalar(0, 160, 0), 2, cv::LINE_AA, shift);
    cv::line(img, px(s.head<2>()), px(tip), cv::Scalar(0, 160, 0), 2, cv::LINE_AA, shift);
  }
  cv::putText(img,
              world.name + "  (1 m grid)",
              cv::Point(8, 20),
              cv::FONT_HERSHEY_SIMPLEX,
              0.5,
              cv::Scalar(0, 0, 0),
              1,
              cv::LINE_AA);
  return img;
}

}  // namespace omnivert::sim
