#pragma once
// Simulated sensors: wheel encoders of a differential-drive robot (Sec. 7, eq. 14-15, with
// the Chong-Kleeman noise of eq. 31) and the image sensor (gain flicker, blur, noise,
// saturation). All randomness comes from the generator passed in: seeded, reproducible.

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/sim/trajectory.hpp"

namespace omnivert::sim {

struct WheelConfig {
  double rate_hz = 50.0;
  double wheel_base = 0.40;  // e [m], the nominal value written to wheel0/sensor.yaml
  // Chong-Kleeman (eq. 31): each reported increment d of a wheel differs from the true one
  // by a zero-mean Gaussian of variance K |d| (K [m]).
  double odometry_k = 1e-5;
  // Systematic errors: a wheel reports (1 + radius_error) times its true travel; the true
  // wheel base is wheel_base * (1 + wheel_base_error).
  double radius_error_left = 0.0;
  double radius_error_right = 0.0;
  double wheel_base_error = 0.0;
  // Output unit: meters, or integer ticks (ticks_per_meter_*) on counters of counter_bits
  // bits that wrap (0: no wrapping).
  bool ticks = false;
  double ticks_per_meter_left = 20000.0;
  double ticks_per_meter_right = 20000.0;
  int counter_bits = 0;

  double true_wheel_base() const { return wheel_base * (1.0 + wheel_base_error); }
};

// Cumulative wheel travel sampled at the wheel rate.
struct WheelSamples {
  std::vector<double> t;                      // [s] from the start of the motion
  std::vector<double> true_left, true_right;  // true cumulative travel [m]
  std::vector<double> left, right;            // reported cumulative travel [m] (noise, errors)
};

// True cumulative travel (left, right) [m] of the wheels at time t for wheel base e:
// d_L = integral of (v - omega e / 2), d_R = integral of (v + omega e / 2) (eq. 15 inverted).
Eigen::Vector2d true_wheel_travel(const std::vector<MotionPiece>& motion, double t, double e);

// Samples t = 0, 1/rate, ... up to and including the first sample at or after t_end.
WheelSamples simulate_wheels(const std::vector<MotionPiece>& motion,
                             double t_end,
                             const WheelConfig& config,
                             std::mt19937_64& rng);

// Reported cumulative travel as integer ticks, wrapped to [0, 2^counter_bits) when
// counter_bits > 0.
std::int64_t to_ticks(double meters, double ticks_per_meter, int counter_bits);

struct ImageSensor {
  double noise_sigma = 2.0;    // additive Gaussian noise [grey levels]
  double gain_flicker = 0.03;  // per-frame gain ~ N(1, gain_flicker)
  double exposure = 1.0;       // mean gain; > 1 saturates bright walls and windows
  double blur_sigma = 0.0;     // Gaussian optical blur [px]; 0: none
  // Motion blur: the image is the mean of exposure_samples renders spread evenly over
  // [t - T / 2, t + T / 2] (T = exposure_time [s]) as the robot moves; 0: instantaneous.
  double exposure_time = 0.0;
  int exposure_samples = 8;
  // 1..100: images written as JPEG at this quality (the artefacts of a compressing camera);
  // 0: PNG, lossless.
  int jpeg_quality = 0;
  // Vignetting: the lens's gain falls to 1 - vignetting at the rim (r = r_max), as
  // 1 - vignetting (r / r_max)^2.
  double vignetting = 0.0;
  // Light that varies across the room: each pixel's ray has the gain
  // 1 + light_gradient cos(world azimuth - light_azimuth), brightest towards light_azimuth
  // [rad] (a window wall); light_gradient 1/3 is a factor of 2 between the two sides.
  double light_gradient = 0.0;
  double light_azimuth = 0.0;

  // Empty when usable; otherwise what is wrong.
  std::string validate() const;
};

// Turns a noise-free rendering into the 8-bit image the camera delivers: gain (exposure and
// flicker), blur, additive noise, saturation to 0..255 and rounding, in that order.
void apply_image_sensor(const cv::Mat1f& clean,
                        const ImageSensor& sensor,
                        std::mt19937_64& rng,
                        cv::Mat1b& out);

// Multiplies a rendering by the light across the room (ImageSensor::light_gradient, for a
// camera whose x-axis points to world azimuth `camera_yaw` [rad]) and the lens's vignetting,
// about the mirror centre (cx, cy) with the rim at r_max [px] and image angle
// a = bearing_sign * bearing (docs/theory/conventions.md).
void apply_lighting(cv::Mat1f& image,
                    const ImageSensor& sensor,
                    double cx,
                    double cy,
                    double r_max,
                    int bearing_sign,
                    double camera_yaw);

}  // namespace omnivert::sim
