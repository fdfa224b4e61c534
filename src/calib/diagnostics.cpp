#include "omnivert/calib/diagnostics.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "calib/noise_check.hpp"
#include "calib/updater.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

namespace internal {

WheelCheck wheel_check(const Built& b,
                       const CalibrationRun& run,
                       const CalibrationOptions& options) {
  WheelCheck out;
  const double K = options.robot.odometry_K * options.refinement.odometry_inflation,
               e = options.robot.wheel_base;
  if (!(e > 0.0)) return out;
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d g = Eigen::Vector2d::Zero();
  const std::size_t n = std::min(run.frames.size(), b.poses.size());
  for (std::size_t k = 1; k < n; ++k) {
    const FrameInput& f = run.frames[k];
    const double turn = (f.d_right - f.d_left) / e;  // eq. (15)
    const double dist = 0.5 * (f.d_right + f.d_left);
    if (turn == 0.0 && dist == 0.0) continue;
    double v;  // variance of (d_right - d_left)
    if (!f.covariance_per_K.isZero())
      v = K *
          (f.covariance_per_K(0, 0) + f.covariance_per_K(1, 1) - 2.0 * f.covariance_per_K(0, 1));
    else
      v = K * (std::abs(f.d_right) + std::abs(f.d_left));
    v = (v + 2.0 * options.robot.odometry_variance_floor) / (e * e);
    if (!(v > 0.0)) continue;
    const double robot = angle_diff(b.poses[k][2], b.poses[k - 1][2]);
    const double r = angle_diff(turn, robot);
    const Eigen::Vector2d x(robot, dist);
    A += x * x.transpose() / v;
    g += x * r / v;
    ++out.frames;
  }
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(A);
  if (out.frames < 3 || ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0).all())
    return out;
  const Eigen::Vector2d ab = ldlt.solve(g);
  const Eigen::Matrix2d C = ldlt.solve(Eigen::Matrix2d::Identity());
  if (!ab.allFinite() || !C.allFinite()) return out;
  out.rotation_scale = ab(0);
  out.drift_per_m = ab(1);
  out.sigma_rotation_scale = std::sqrt(C(0, 0));
  out.sigma_drift_per_m = std::sqrt(C(1, 1));
  out.chi2 = ab.dot(A * ab);
  out.wheel_base = e;
  out.ok = true;
  return out;
}

}  // namespace internal

bool wheel_check_rejects_model(const WheelCheck& check, double level) {
  return check.ok && check.chi2 > chi2_quantile(1.0 - level, 2);
}

double noise_check_limit(int tracks, double level) {
  return chi2_quantile(1.0 - level, tracks) / tracks;
}

namespace {

// Whether a check can be judged at `level` (noise_check_rejects_model and
// noise_check_finds_less_noise).
bool judgeable(const BatchNoiseCheck& check, double level) {
  return check.ok && check.clusters >= 2 && level > 0.0 && level < 0.5;
}

}  // namespace

bool noise_check_rejects_model(const BatchNoiseCheck& check, double level) {
  return judgeable(check, level) && check.scale > noise_check_limit(check.clusters, level);
}

double noise_check_lower_limit(int tracks, double level) {
  return chi2_quantile(level, tracks) / tracks;
}

bool noise_check_finds_less_noise(const BatchNoiseCheck& check, double level) {
  return judgeable(check, level) && check.scale < noise_check_lower_limit(check.clusters, level);
}

NoiseVerdict noise_check_verdict(const BatchNoiseCheck& check, double level, double lower_level) {
  if (noise_check_rejects_model(check, level)) return NoiseVerdict::kMoreNoise;
  if (noise_check_finds_less_noise(check, lower_level)) return NoiseVerdict::kLessNoise;
  return NoiseVerdict::kAgrees;
}

}  // namespace omnivert::calib
