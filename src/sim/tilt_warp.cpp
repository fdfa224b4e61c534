#include "sim/tilt_warp.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "omnivert/core/tilt.hpp"

namespace omnivert::sim {

TiltWarp::TiltWarp(const CatadioptricCamera& camera,
                   const World& world,
                   const std::vector<int>& px_index,
                   const std::vector<float>& px_weight)
    : px_index_(px_index), px_weight_(px_weight) {
  const Eigen::Matrix3d R =
      tilt_rotation(camera.tilt_deg * M_PI / 180.0, camera.tilt_direction_deg * M_PI / 180.0);
  // Upright direction (bearing, elevation) of every warped pixel, and the radii they span.
  std::vector<Eigen::Vector2d> dirs(px_index_.size());
  double r_lo = 1e9, r_hi = 0.0;
  for (std::size_t k = 0; k < px_index_.size(); ++k) {
    const int u = px_index_[k] % camera.width, v = px_index_[k] / camera.width;
    const double du = u - camera.cx, dv = v - camera.cy;
    const double beta = camera.bearing_sign * std::atan2(dv, du);
    const double el = camera.elevation_of_radius(std::hypot(du, dv));
    const Eigen::Vector3d d = R * unit_direction(beta, el);
    dirs[k] = {std::atan2(d.y(), d.x()), std::asin(std::clamp(d.z(), -1.0, 1.0))};
    const double r = camera.radius_of_elevation(dirs[k].y());
    r_lo = std::min(r_lo, r);
    r_hi = std::max(r_hi, r);
  }
  // The upright camera: same model, an annulus holding every warped pixel with 2 px to spare
  // for the bilinear footprint, centred in a padded image.
  CatadioptricCamera up = camera;
  up.tilt_deg = 0.0;
  up.tilt_direction_deg = 0.0;
  up.r_min = std::max(4.0, r_lo + 1.0);  // its self-reflection starts 3 px inside
  up.r_max = r_hi + 2.0;
  const int pad = static_cast<int>(std::ceil(std::max(0.0, up.r_max - camera.r_max))) + 8;
  up.cx = camera.cx + pad;
  up.cy = camera.cy + pad;
  up.width = camera.width + 2 * pad;
  up.height = camera.height + 2 * pad;
  upright_ = std::make_unique<Renderer>(up, world);
  map_x_ = cv::Mat1f(camera.height, camera.width, -1.0f);
  map_y_ = cv::Mat1f(camera.height, camera.width, -1.0f);
  for (std::size_t k = 0; k < px_index_.size(); ++k) {
    const Eigen::Vector2d p = up.pixel_of(dirs[k].x(), dirs[k].y());
    map_x_(px_index_[k]) = static_cast<float>(p.x());
    map_y_(px_index_[k]) = static_cast<float>(p.y());
  }
}

void TiltWarp::render(const CameraPose& pose, const cv::Mat1f& background, cv::Mat1f& image) const {
  cv::Mat1f src, warped;
  upright_->render(pose, src);
  cv::remap(src, warped, map_x_, map_y_, cv::INTER_CUBIC, cv::BORDER_REPLICATE);
  background.copyTo(image);
  for (std::size_t k = 0; k < px_index_.size(); ++k) {
    const int idx = px_index_[k];
    const float w = px_weight_[k];
    image(idx) = w * warped(idx) + (1.0f - w) * image(idx);
  }
}

}  // namespace omnivert::sim
