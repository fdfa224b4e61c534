#pragma once
// The Ceres cost functors of the batch problems (refinement, bound, start-up window).

#include <Eigen/Core>
#include <cmath>

namespace omnivert::calib::internal {

// Odometry factor between poses i and j = i + 1: eq. (14)-(15) inverted. The pose change
// gives d_theta and, along the mid-step heading, d_rho; the motion across it must be the
// wheels' (FrameInput::lateral, 0 for one step of eq. 14).
// The three residuals are whitened by W (W^T W = the inverse covariance of the wheels' step,
// FrameInput::covariance_per_K, or diagonal for one step).
struct OdometryResidual {
  double d_right, d_left, lateral_measured, e;
  Eigen::Matrix3d W;
  template <typename T>
  bool operator()(const T* pi, const T* pj, T* r) const {
    const T dth = pj[2] - pi[2];
    const T mid = pi[2] + 0.5 * dth;
    const T dx = pj[0] - pi[0], dy = pj[1] - pi[1];
    const T c = cos(mid), s = sin(mid);
    const T d_rho = c * dx + s * dy;
    const T lateral = -s * dx + c * dy;
    const T dR = d_rho + 0.5 * e * dth;  // eq. (15) solved for the wheels
    const T dL = d_rho - 0.5 * e * dth;
    const T v[3] = {dR - d_right, dL - d_left, lateral - lateral_measured};
    for (int i = 0; i < 3; ++i) r[i] = W(i, 0) * v[0] + W(i, 1) * v[1] + W(i, 2) * v[2];
    return true;
  }
};

// Bearing factor: beta = atan2(y_f - y_C, x_f - x_C) - (theta_R + phi + psi), residual wrapped
// to (-pi, pi] and whitened; `offset` is added to the prediction (a track's constant error).
template <typename T>
T bearing_residual(
    double beta, double inv_sigma, const T* pose, const T* f, const T* ex, const T& offset) {
  const T a = pose[2] + ex[0];
  const T xc = pose[0] + ex[1] * cos(a);
  const T yc = pose[1] + ex[1] * sin(a);
  const T pred = atan2(f[1] - yc, f[0] - xc) - (pose[2] + ex[0] + ex[2]) + offset;
  const T d = T(beta) - pred;
  return atan2(sin(d), cos(d)) * inv_sigma;
}

struct BearingResidual {
  double beta, inv_sigma;
  template <typename T>
  bool operator()(const T* pose, const T* f, const T* ex, T* r) const {
    r[0] = bearing_residual(beta, inv_sigma, pose, f, ex, T(0.0));
    return true;
  }
};

// CalibrationOptions::noise.track_bias_sigma: the bearing with the track's constant error b added
// to eq. (30)'s prediction, and b's prior.
struct BiasedBearingResidual {
  double beta, inv_sigma;
  template <typename T>
  bool operator()(const T* pose, const T* f, const T* ex, const T* bias, T* r) const {
    r[0] = bearing_residual(beta, inv_sigma, pose, f, ex, bias[0]);
    return true;
  }
};

struct BiasPrior {
  double inv_sigma;
  template <typename T>
  bool operator()(const T* bias, T* r) const {
    r[0] = bias[0] * inv_sigma;
    return true;
  }
};

// Ext prior: (phi, rho, psi) ~ N(prior, diag(sigma^2)), angles wrapped.
struct ExtrinsicsPrior {
  Eigen::Vector3d mean, inv_sigma;
  template <typename T>
  bool operator()(const T* ex, T* r) const {
    const T dphi = ex[0] - mean(0), dpsi = ex[2] - mean(2);
    r[0] = atan2(sin(dphi), cos(dphi)) * inv_sigma(0);
    r[1] = (ex[1] - mean(1)) * inv_sigma(1);
    r[2] = atan2(sin(dpsi), cos(dpsi)) * inv_sigma(2);
    return true;
  }
};

// Inverse-depth prior of a track: 1 / |f - C| ~ N(q0, (scale sigma_q)^2), C the camera centre
// at the track's first frame. Weak (scale 100 by default): it only keeps a track without
// parallax in the window finite. (At full strength it biases the distant features of the
// paper's setup, q0 being a midpoint, and the window with them: measured 1 run in 20 with
// NEES ~ 500.)
struct InverseDepthPrior {
  double q0, inv_sigma;
  template <typename T>
  bool operator()(const T* pose, const T* f, const T* ex, T* r) const {
    const T a = pose[2] + ex[0];
    const T dx = f[0] - (pose[0] + ex[1] * cos(a));
    const T dy = f[1] - (pose[1] + ex[1] * sin(a));
    r[0] = (T(1.0) / sqrt(dx * dx + dy * dy) - q0) * inv_sigma;
    return true;
  }
};

}  // namespace omnivert::calib::internal
