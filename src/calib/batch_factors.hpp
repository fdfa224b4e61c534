#pragma once
// The Ceres cost functors of the batch problems (refinement, bound, start-up window).

#include <ceres/jet.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "omnivert/calib/types.hpp"

namespace omnivert::calib::internal {

// Odometry factor between poses i and j = i + 1: eq. (14)-(15) inverted. The pose change
// gives d_theta and, along the mid-step heading, d_rho; the motion across it must be the
// wheels' (d_right, d_left and FrameInput::lateral, 0 for one step of eq. 14).
// The three residuals are whitened by W (W^T W = the inverse covariance of the wheels' step,
// FrameInput::covariance_per_K, or diagonal for one step).
template <typename T, typename L>
void odometry_residual(const T* pi,
                       const T* pj,
                       const T& d_right,
                       const T& d_left,
                       const L& lateral_measured,
                       double e,
                       const Eigen::Matrix3d& W,
                       T* r) {
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
}

struct OdometryResidual {
  double d_right, d_left, lateral_measured, e;
  Eigen::Matrix3d W;
  template <typename T>
  bool operator()(const T* pi, const T* pj, T* r) const {
    odometry_residual(pi, pj, T(d_right), T(d_left), lateral_measured, e, W, r);
    return true;
  }
};

inline double scalar_part(double x) { return x; }
template <typename J, int N>
double scalar_part(const ceres::Jet<J, N>& x) {
  return scalar_part(x.a);
}

// A wheel's cumulative travel at odometry time x - dS: linear between the samples (t, v), held
// beyond the ends; in dS the slope of the segment it falls in.
template <typename T>
T travel_at(const std::vector<double>& t, const std::vector<double>& v, double x, const T& dS) {
  const T at = T(x) - dS;
  const double a = scalar_part(at);
  if (a <= t.front()) return T(v.front());
  if (a >= t.back()) return T(v.back());
  const std::size_t j =
      static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), a) - t.begin());
  const std::size_t i = j - 1;
  return T(v[i]) + (at - t[i]) * ((v[j] - v[i]) / (t[j] - t[i]));
}

// The wheels' motion between odometry times t_i - dS and t_j - dS as FrameInput holds it
// (compose_wheel_steps): eq. (14) per wheel sample step, the travel at the two ends
// interpolated, composed and returned as (d_right, d_left, lateral) about the mid-step
// heading. Each piece is smooth in dS; where dS moves an end past a sample, the pieces meet.
template <typename T>
void compose_between(const WheelClock& c, double t_i, double t_j, const T& dS, double e, T out[3]) {
  T right = travel_at(c.t, c.right, t_i, dS), left = travel_at(c.t, c.left, t_i, dS);
  T x(0.0), y(0.0), th(0.0);
  const auto step = [&](const T& r, const T& l) {
    const T d_rho = 0.5 * ((r - right) + (l - left)), d_th = ((r - right) - (l - left)) / e;
    const T mid = th + 0.5 * d_th;  // eq. (14): the heading at mid-step
    x += d_rho * cos(mid);
    y += d_rho * sin(mid);
    th += d_th;
    right = r;
    left = l;
  };
  const double a = scalar_part(T(t_i) - dS), b = scalar_part(T(t_j) - dS);
  for (std::size_t k =
           static_cast<std::size_t>(std::upper_bound(c.t.begin(), c.t.end(), a) - c.t.begin());
       k < c.t.size() && c.t[k] < b;
       ++k)
    step(T(c.right[k]), T(c.left[k]));
  step(travel_at(c.t, c.right, t_j, dS), travel_at(c.t, c.left, t_j, dS));
  const T mid = 0.5 * th, cm = cos(mid), sm = sin(mid);
  const T along = cm * x + sm * y;
  out[0] = along + 0.5 * e * th;
  out[1] = along - 0.5 * e * th;
  out[2] = -sm * x + cm * y;
}

// The odometry factor with the time offset's correction dS (RefinementOptions::
// estimate_time_offset): frames i and j taken at odometry times t_i - dS and t_j - dS, the
// wheels' motion between them composed there (compose_between); the covariance stays that at
// dS = 0.
struct TimedOdometryResidual {
  OdometryResidual step;
  std::shared_ptr<const WheelClock> clock;
  double t_i, t_j;
  template <typename T>
  bool operator()(const T* pi, const T* pj, const T* dS, T* r) const {
    T m[3];
    compose_between(*clock, t_i, t_j, dS[0], step.e, m);
    odometry_residual(pi, pj, m[0], m[1], m[2], step.e, step.W, r);
    return true;
  }
};

// dS ~ N(0, sigma^2) (RefinementOptions::time_offset_prior_sigma_s).
struct TimeOffsetPrior {
  double inv_sigma;
  template <typename T>
  bool operator()(const T* dS, T* r) const {
    r[0] = dS[0] * inv_sigma;
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
