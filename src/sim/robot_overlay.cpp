#include "omnivert/sim/robot_overlay.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"

namespace omnivert::sim {

bool RobotOverlay::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  for (double a : strut_angles_deg)
    if (!std::isfinite(a)) return fail("strut angles must be finite");
  if (!(strut_width_px > 0 && strut_width_px <= 100))
    return fail("strut width must be in (0, 100] px");
  if (!(strut_inner_px >= 0)) return fail("strut inner radius must not be negative");
  if (!(reflection_width_deg >= 0 && reflection_width_deg <= 360))
    return fail("reflection width must be in [0, 360] degrees");
  if (!(reflection_r_inner_px >= 0 && reflection_r_outer_px >= 0))
    return fail("reflection radii must not be negative");
  if (reflection_r_outer_px > 0 && !(reflection_r_inner_px < reflection_r_outer_px))
    return fail("the reflection's inner radius must be below its outer radius");
  if (!(strut_grey >= 0 && strut_grey <= 255 && reflection_grey >= 0 && reflection_grey <= 255))
    return fail("overlay grey levels must be in [0, 255]");
  if (!(mask_margin_px >= 0 && mask_margin_px <= 20))
    return fail("mask margin must be in [0, 20] px");
  return true;
}

namespace {

// Fraction of the pixel (u, v) inside `inside(x, y)`, from 4 x 4 samples.
template <typename F>
float pixel_coverage(int u, int v, F&& inside) {
  int n = 0;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) n += inside(u - 0.375 + 0.25 * i, v - 0.375 + 0.25 * j) ? 1 : 0;
  return n / 16.0f;
}

// Paints coverage (the maximum with what is there) and grey over the pixels of a box.
template <typename F>
void paint_shape(OverlayPicture& p, cv::Rect box, float grey, F&& inside) {
  box &= cv::Rect(0, 0, p.coverage.cols, p.coverage.rows);
  for (int v = box.y; v < box.y + box.height; ++v) {
    for (int u = box.x; u < box.x + box.width; ++u) {
      const float c = pixel_coverage(u, v, inside);
      if (c <= 0.0f || c < p.coverage(v, u)) continue;
      p.coverage(v, u) = c;
      p.grey(v, u) = grey;
    }
  }
}

}  // namespace

OverlayPicture overlay_picture(const RobotOverlay& o, const CatadioptricCamera& cam) {
  OverlayPicture p;
  p.coverage = cv::Mat1f::zeros(cam.height, cam.width);
  p.grey = cv::Mat1f::zeros(cam.height, cam.width);
  const double cx = cam.cx, cy = cam.cy;
  if (o.reflection_width_deg > 0) {
    const double r0 = o.reflection_r_outer_px > 0 ? o.reflection_r_inner_px : cam.self_radius();
    const double r1 = o.reflection_r_outer_px > 0 ? o.reflection_r_outer_px
                                                  : cam.r_min + 0.3 * (cam.r_max - cam.r_min);
    const double a0 = deg2rad(o.reflection_angle_deg);
    const double half = deg2rad(0.5 * o.reflection_width_deg);
    const int R = static_cast<int>(std::ceil(r1)) + 1;
    paint_shape(p,
                cv::Rect(static_cast<int>(cx) - R, static_cast<int>(cy) - R, 2 * R + 2, 2 * R + 2),
                static_cast<float>(o.reflection_grey),
                [&](double x, double y) {
                  const double r = std::hypot(x - cx, y - cy);
                  if (r < r0 || r > r1) return false;
                  return std::abs(angle_diff(std::atan2(y - cy, x - cx), a0)) <= half;
                });
  }
  const double r_in = o.strut_inner_px > 0 ? o.strut_inner_px : cam.r_min;
  const double r_out = cam.rim_radius() + 6.0;  // beyond the rim: into the dark border
  const double hw = 0.5 * o.strut_width_px;
  for (double deg : o.strut_angles_deg) {
    const double a = deg2rad(deg);
    const double ca = std::cos(a), sa = std::sin(a);
    const double xs[2] = {cx + r_in * ca, cx + r_out * ca},
                 ys[2] = {cy + r_in * sa, cy + r_out * sa};
    const int u0 = static_cast<int>(std::floor(std::min(xs[0], xs[1]) - hw)) - 1;
    const int v0 = static_cast<int>(std::floor(std::min(ys[0], ys[1]) - hw)) - 1;
    const int u1 = static_cast<int>(std::ceil(std::max(xs[0], xs[1]) + hw)) + 1;
    const int v1 = static_cast<int>(std::ceil(std::max(ys[0], ys[1]) + hw)) + 1;
    paint_shape(p,
                cv::Rect(u0, v0, u1 - u0 + 1, v1 - v0 + 1),
                static_cast<float>(o.strut_grey),
                [&](double x, double y) {
                  const double fwd = (x - cx) * ca + (y - cy) * sa;
                  const double lat = -(x - cx) * sa + (y - cy) * ca;
                  return fwd >= r_in && fwd <= r_out && std::abs(lat) <= hw;
                });
  }
  return p;
}

void paint_overlay(const OverlayPicture& p, cv::Mat1f& image) {
  CV_Assert(image.size() == p.coverage.size());
  for (int v = 0; v < image.rows; ++v) {
    const float* c = p.coverage.ptr<float>(v);
    const float* g = p.grey.ptr<float>(v);
    float* im = image.ptr<float>(v);
    for (int u = 0; u < image.cols; ++u)
      if (c[u] > 0.0f) im[u] = (1.0f - c[u]) * im[u] + c[u] * g[u];
  }
}

cv::Mat overlay_mask(const OverlayPicture& p, double margin_px) {
  cv::Mat masked;
  cv::compare(p.coverage, 0.0, masked, cv::CMP_GT);
  const int m = static_cast<int>(std::ceil(margin_px));
  if (m > 0) {
    cv::dilate(
        masked, masked, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * m + 1, 2 * m + 1}));
  }
  cv::Mat usable;
  cv::bitwise_not(masked, usable);
  return usable;
}

}  // namespace omnivert::sim
