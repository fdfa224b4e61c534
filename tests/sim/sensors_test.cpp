// The simulated sensors have the stated noise: Chong-Kleeman wheel increments with variance
// K |d| (eq. 31), image noise of the stated sigma, gain flicker of the stated sigma; and the
// systematic errors do what they say.

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/sim/sensors.hpp"
#include "omnivert/sim/trajectory.hpp"

namespace omnivert::sim {
namespace {

std::vector<MotionPiece> test_motion() {
  Trajectory t = load_trajectory("zigzag");
  t.speed = 0.3;
  t.segments.push_back({Segment::Kind::kArc, 3.0, 1.0, 0.0});
  t.segments.push_back({Segment::Kind::kStraight, -2.0, 0.0, 0.0});
  return t.pieces(Pose2::Zero());
}

TEST(WheelNoise, IncrementVarianceIsKTimesDistance) {
  const auto motion = test_motion();
  WheelConfig c;
  c.odometry_k = 4e-5;
  // Normalised residuals (reported - true) / sqrt(|d|) have variance K.
  double sum = 0, sum2 = 0;
  long n = 0;
  for (int run = 0; run < 20; ++run) {
    std::mt19937_64 rng(100 + run);
    const WheelSamples w = simulate_wheels(motion, duration(motion), c, rng);
    for (std::size_t i = 1; i < w.t.size(); ++i) {
      for (int side = 0; side < 2; ++side) {
        const auto& tr = side ? w.true_right : w.true_left;
        const auto& me = side ? w.right : w.left;
        const double d = tr[i] - tr[i - 1];
        if (std::abs(d) < 1e-6) continue;
        const double e = ((me[i] - me[i - 1]) - d) / std::sqrt(std::abs(d));
        sum += e;
        sum2 += e * e;
        ++n;
      }
    }
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  std::printf("wheel increments: n = %ld, variance / (K|d|) = %.4f, mean %.2e\n",
              n,
              var / c.odometry_k,
              mean);
  ASSERT_GT(n, 20000);
  // Relative standard error of a variance estimate is sqrt(2/n) (< 1% here): 5% is > 5 sigma.
  EXPECT_NEAR(var / c.odometry_k, 1.0, 0.05);
  EXPECT_NEAR(mean / std::sqrt(c.odometry_k), 0.0, 5.0 / std::sqrt(static_cast<double>(n)));
}

TEST(WheelNoise, NoNoiseGivesTrueTravelAndEq15Inverts) {
  const auto motion = test_motion();
  WheelConfig c;
  c.odometry_k = 0;
  std::mt19937_64 rng(1);
  const WheelSamples w = simulate_wheels(motion, duration(motion), c, rng);
  for (std::size_t i = 0; i < w.t.size(); ++i) {
    ASSERT_DOUBLE_EQ(w.left[i], w.true_left[i]);
    ASSERT_DOUBLE_EQ(w.right[i], w.true_right[i]);
  }
  // Eq. (15): over a turn in place of angle a, d_R - d_L = e a.
  Trajectory t;
  t.segments = {{Segment::Kind::kTurn, 0, 1.5, 0}};
  const auto turn = t.pieces(Pose2::Zero());
  const Eigen::Vector2d d = true_wheel_travel(turn, duration(turn), 0.4);
  EXPECT_NEAR((d.y() - d.x()) / 0.4, 1.5, 1e-12);
  EXPECT_NEAR(0.5 * (d.x() + d.y()), 0.0, 1e-12);
}

TEST(WheelNoise, SystematicErrorsScaleTheReportedTravel) {
  Trajectory t;
  t.segments = {{Segment::Kind::kStraight, 2.0, 0, 0}, {Segment::Kind::kTurn, 0, 1.0, 0}};
  const auto motion = t.pieces(Pose2::Zero());
  WheelConfig c;
  c.odometry_k = 0;
  c.radius_error_left = 0.01;
  c.radius_error_right = -0.02;
  c.wheel_base_error = 0.05;
  std::mt19937_64 rng(1);
  const WheelSamples w = simulate_wheels(motion, duration(motion), c, rng);
  // True travel uses the true wheel base 0.42: left = 2 - 0.21, right = 2 + 0.21.
  EXPECT_NEAR(w.true_left.back(), 2.0 - 0.21, 1e-9);
  EXPECT_NEAR(w.true_right.back(), 2.0 + 0.21, 1e-9);
  EXPECT_NEAR(w.left.back(), 1.01 * (2.0 - 0.21), 1e-9);
  EXPECT_NEAR(w.right.back(), 0.98 * (2.0 + 0.21), 1e-9);
}

TEST(WheelNoise, TicksWrapModuloCounterBits) {
  EXPECT_EQ(to_ticks(0.5, 1000, 0), 500);
  EXPECT_EQ(to_ticks(5.0, 1000, 12), 5000 - 4096);
  EXPECT_EQ(to_ticks(-0.001, 1000, 12), 4095);
}

TEST(ImageSensor, NoiseHasTheStatedSigma) {
  const cv::Mat1f flat(480, 640, 100.0f);
  ImageSensor s;
  s.noise_sigma = 5.0;
  s.gain_flicker = 0.0;
  std::mt19937_64 rng(3);
  cv::Mat1b out;
  apply_image_sensor(flat, s, rng, out);
  cv::Scalar mean, sd;
  cv::meanStdDev(out, mean, sd);
  // Rounding to integers adds 1/12 to the variance.
  const double expected = s.noise_sigma * s.noise_sigma + 1.0 / 12.0;
  std::printf("image noise: variance %.3f, expected %.3f\n", sd[0] * sd[0], expected);
  EXPECT_NEAR(sd[0] * sd[0] / expected, 1.0, 0.02);  // n = 307200: relative s.e. 0.26%
  EXPECT_NEAR(mean[0], 100.0, 0.05);
}

TEST(ImageSensor, GainFlickerHasTheStatedSigma) {
  const cv::Mat1f flat(8, 8, 100.0f);
  ImageSensor s;
  s.noise_sigma = 0.0;
  s.gain_flicker = 0.04;
  std::mt19937_64 rng(4);
  double sum = 0, sum2 = 0;
  const int n = 3000;
  cv::Mat1f clean(8, 8, 100.0f);
  for (int i = 0; i < n; ++i) {
    cv::Mat1b out;
    apply_image_sensor(clean, s, rng, out);
    const double g = cv::mean(out)[0] / 100.0;
    sum += g;
    sum2 += g * g;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  std::printf("gain flicker: sigma %.4f, expected %.4f\n", sd, s.gain_flicker);
  EXPECT_NEAR(sd / s.gain_flicker, 1.0, 0.08);  // relative s.e. 1.3%, plus rounding
  EXPECT_NEAR(mean, 1.0, 0.005);
}

TEST(ImageSensor, SaturatesAndIsReproducible) {
  cv::Mat1f img(4, 4, 200.0f);
  ImageSensor s;
  s.exposure = 2.0;
  s.gain_flicker = 0;
  s.noise_sigma = 0;
  std::mt19937_64 rng(1);
  cv::Mat1b out;
  apply_image_sensor(img, s, rng, out);
  EXPECT_EQ(out(0, 0), 255);
  ImageSensor n;
  cv::Mat1b a, b;
  std::mt19937_64 r1(9), r2(9);
  apply_image_sensor(img, n, r1, a);
  apply_image_sensor(img, n, r2, b);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

TEST(ImageSensor, LightAndVignettingHaveTheStatedGains) {
  // A uniform 100 about the centre (50.5, 40.25), rim at 40 px: at the centre the light's gain
  // alone; on the rim towards the light 100 (1 - v)(1 + g), away from it 100 (1 - v)(1 - g).
  ImageSensor s;
  s.vignetting = 0.3;
  s.light_gradient = 1.0 / 3.0;
  s.light_azimuth = deg2rad(90.0);
  const double cx = 50.5, cy = 40.25, yaw = deg2rad(60.0);
  for (int sign : {1, -1}) {
    cv::Mat1f img(81, 101, 100.0f);
    apply_lighting(img, s, cx, cy, 40.0, sign, yaw);
    // The pixel whose bearing points at the light: camera bearing 30 deg, image angle
    // sign * 30 deg; the opposite one at bearing 210 deg.
    const auto at = [&](double bearing_deg, double r) {
      const double a = sign * deg2rad(bearing_deg);
      const double u = cx + r * std::cos(a), v = cy + r * std::sin(a);
      cv::Mat1f px;
      cv::getRectSubPix(
          img, cv::Size(1, 1), cv::Point2f(static_cast<float>(u), static_cast<float>(v)), px);
      return static_cast<double>(px(0, 0));
    };
    EXPECT_NEAR(at(30.0, 40.0), 100 * 0.7 * (4.0 / 3.0), 0.6) << sign;
    EXPECT_NEAR(at(210.0, 40.0), 100 * 0.7 * (2.0 / 3.0), 0.6) << sign;
    EXPECT_NEAR(at(120.0, 20.0), 100 * (1 - 0.3 * 0.25), 0.6) << sign;  // across: cos 90 = 0
  }
  ImageSensor none;
  cv::Mat1f img(10, 10, 100.0f);
  apply_lighting(img, none, 5, 5, 4, 1, 0.3);
  EXPECT_EQ(cv::norm(img - 100.0f, cv::NORM_INF), 0.0);
  s.jpeg_quality = 101;
  EXPECT_NE(s.validate(), "");
  s.jpeg_quality = 75;
  s.vignetting = 1.0;
  EXPECT_NE(s.validate(), "");
}

}  // namespace
}  // namespace omnivert::sim
