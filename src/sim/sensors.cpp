#include "omnivert/sim/sensors.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace omnivert::sim {

Eigen::Vector2d true_wheel_travel(const std::vector<MotionPiece>& motion, double t, double e) {
  Eigen::Vector2d d = Eigen::Vector2d::Zero();
  for (const MotionPiece& m : motion) {
    if (t <= m.t0) break;
    const double dt = std::min(t, m.t1) - m.t0;
    d.x() += (m.v - 0.5 * m.omega * e) * dt;
    d.y() += (m.v + 0.5 * m.omega * e) * dt;
  }
  return d;
}

WheelSamples simulate_wheels(const std::vector<MotionPiece>& motion,
                             double t_end,
                             const WheelConfig& c,
                             std::mt19937_64& rng) {
  WheelSamples w;
  const double e = c.true_wheel_base();
  const double step = 1.0 / c.rate_hz;
  std::normal_distribution<double> n01(0.0, 1.0);
  double left = 0.0, right = 0.0;
  Eigen::Vector2d prev = Eigen::Vector2d::Zero();
  for (long k = 0;; ++k) {
    const double t = static_cast<double>(k) * step;
    const Eigen::Vector2d now = true_wheel_travel(motion, t, e);
    const Eigen::Vector2d d = now - prev;
    prev = now;
    // Eq. (31): reported increment = true increment (with the wheel's scale error) plus
    // N(0, K |d|).
    left +=
        d.x() * (1.0 + c.radius_error_left) + std::sqrt(c.odometry_k * std::abs(d.x())) * n01(rng);
    right +=
        d.y() * (1.0 + c.radius_error_right) + std::sqrt(c.odometry_k * std::abs(d.y())) * n01(rng);
    w.t.push_back(t);
    w.true_left.push_back(now.x());
    w.true_right.push_back(now.y());
    w.left.push_back(left);
    w.right.push_back(right);
    if (t >= t_end) break;
  }
  return w;
}

std::int64_t to_ticks(double meters, double ticks_per_meter, int counter_bits) {
  std::int64_t t = std::llround(meters * ticks_per_meter);
  if (counter_bits > 0 && counter_bits < 63) {
    const std::int64_t mod = std::int64_t{1} << counter_bits;
    t %= mod;
    if (t < 0) t += mod;
  }
  return t;
}

std::string ImageSensor::validate() const {
  if (!(exposure_time >= 0.0) || !std::isfinite(exposure_time))
    return "the exposure time must be >= 0 [s]";
  if (exposure_samples < 1 || exposure_samples > 64) return "exposure_samples must be in 1..64";
  if (jpeg_quality < 0 || jpeg_quality > 100) return "the JPEG quality must be in 0..100 (0: PNG)";
  if (!(vignetting >= 0.0 && vignetting < 1.0)) return "vignetting must be in [0, 1)";
  if (!(light_gradient >= 0.0 && light_gradient < 1.0)) return "light_gradient must be in [0, 1)";
  if (!std::isfinite(light_azimuth)) return "light_azimuth must be finite";
  return {};
}

void apply_lighting(cv::Mat1f& image,
                    const ImageSensor& s,
                    double cx,
                    double cy,
                    double r_max,
                    int bearing_sign,
                    double camera_yaw) {
  if (s.vignetting == 0.0 && s.light_gradient == 0.0) return;
  for (int v = 0; v < image.rows; ++v) {
    float* row = image[v];
    for (int u = 0; u < image.cols; ++u) {
      const double dx = u - cx, dy = v - cy;
      double gain = 1.0 - s.vignetting * (dx * dx + dy * dy) / (r_max * r_max);
      if (s.light_gradient != 0.0) {
        const double bearing = bearing_sign * std::atan2(dy, dx);  // a = bearing_sign * beta
        gain *= 1.0 + s.light_gradient * std::cos(camera_yaw + bearing - s.light_azimuth);
      }
      row[u] = static_cast<float>(row[u] * std::max(gain, 0.0));
    }
  }
}

void apply_image_sensor(const cv::Mat1f& clean,
                        const ImageSensor& s,
                        std::mt19937_64& rng,
                        cv::Mat1b& out) {
  std::normal_distribution<double> n01(0.0, 1.0);
  const double gain = s.exposure * (1.0 + s.gain_flicker * n01(rng));
  cv::Mat1f img = clean * gain;
  if (s.blur_sigma > 0.0) cv::GaussianBlur(img, img, cv::Size(0, 0), s.blur_sigma);
  if (s.noise_sigma > 0.0) {
    cv::RNG cvrng(rng());
    cv::Mat1f noise(img.size());
    cvrng.fill(noise, cv::RNG::NORMAL, 0.0, s.noise_sigma);
    img += noise;
  }
  // Saturation and rounding (convertTo clips to 0..255 and rounds to nearest).
  img.convertTo(out, CV_8U);
}

}  // namespace omnivert::sim
