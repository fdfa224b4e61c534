// The warnings calibrate()'s result gives (result_warnings) and the texts they share.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include "calib/updater.hpp"
#include "omnivert/calib/calibrate.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

std::string bearing_noise_text(double bearing_sigma, double track_bias_sigma) {
  char buf[96];
  if (track_bias_sigma > 0.0)
    std::snprintf(buf,
                  sizeof buf,
                  "%.3f deg + %.3f deg per track",
                  rad2deg(bearing_sigma),
                  rad2deg(track_bias_sigma));
  else
    std::snprintf(buf, sizeof buf, "%.3f deg", rad2deg(bearing_sigma));
  return buf;
}

std::string noise_check_flags(const CalibrationResult& r) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "--bearing-sigma %.3f", rad2deg(effective_bearing_sigma(r)));
  std::string out = buf;
  if (r.model.track_bias_sigma > 0.0) {
    std::snprintf(
        buf, sizeof buf, " --track-bias-sigma %.3f", rad2deg(effective_track_bias_sigma(r)));
    out += buf;
  }
  return out;
}

std::string noise_check_chance(double limit, const char* side, double level) {
  char buf[96];
  std::snprintf(
      buf, sizeof buf, "x%.2f or %s has a %g%% chance under it", limit, side, 100.0 * level);
  return buf;
}

namespace {

// The filter's gate refused many bearings after its start-up window.
void warn_gate_refusals(const CalibrationResult& r, std::vector<std::string>* out) {
  char buf[1024];
  // The gate's refusals after the start-up window: the window's own outliers (left out of its
  // batch solve, counted in its frames) are no sign of a filter that diverged. Counted with
  // them, this fires in 343 of 400 zigzag runs from pixels whose estimates are consistent
  // (the window is most of a zigzag run); counted after the window, in 1 of 800 runs of all
  // four rows (ResultWarnings.GateRefusalsCountAfterTheWindow).
  const std::size_t from = r.filter.window_failure.empty()
                               ? static_cast<std::size_t>(std::max(r.filter.window_frames, 0))
                               : 0;
  long used = 0, refused = 0;
  for (std::size_t k = from; k < r.filter.history.size(); ++k) {
    used += r.filter.history[k].num_updates;
    refused += r.filter.history[k].num_rejected;
  }
  const long seen = used + refused;
  if (seen >= 50 && refused > 0.2 * static_cast<double>(seen)) {
    std::snprintf(buf,
                  sizeof(buf),
                  "the filter's chi-square gate refused %ld of %ld bearings (%.0f%%) after its "
                  "start-up window: the filter has probably diverged or the tracks mix lines; "
                  "look at tracks.png%s",
                  refused,
                  seen,
                  100.0 * static_cast<double>(refused) / static_cast<double>(seen),
                  r.refined ? "" : " and run with --refine");
    out->emplace_back(buf);
  }
}

// The start-up window could not be solved.
void warn_window_failure(const CalibrationResult& r, std::vector<std::string>* out) {
  char buf[1024];
  if (!r.filter.window_failure.empty()) {
    std::snprintf(
        buf,
        sizeof(buf),
        "the filter's start-up window (%d frames, solved as a batch) could not be "
        "solved (%s); the filter ran over it from the prior, one frame at a time, and "
        "may be off by more than its sigma%s",
        r.filter.window_frames,
        r.filter.window_failure.c_str(),
        r.refined ? "; the refinement's answer is the one to trust" : ": run with --refine");
    out->emplace_back(buf);
  }
}

// The noise check shows more noise than the model allows.
void warn_more_noise(const CalibrationResult& r, std::vector<std::string>* out) {
  char buf[1024];
  if (r.noise_check.checked && r.noise_check.check.clusters >= 2) {
    // noise_check_rejects_model at the level the run used: under the model the check's scale
    // is about chi-square(G) / G over G tracks.
    const int g = r.noise_check.check.clusters;
    if (noise_check_rejects_model(r.noise_check.check, r.noise_check.level)) {
      std::snprintf(buf,
                    sizeof(buf),
                    "To weight the bearings as the data say, run again with "
                    "%s",
                    noise_check_flags(r).c_str());
      std::string remedy = buf;
      if (!r.refined)
        remedy +=
            "; or add --refine, which splits tracks that slipped onto a neighbouring "
            "line anywhere in the run (the filter splits them only in its start-up window "
            "and then treats each as one feature, which the check sees)";
      std::snprintf(
          buf,
          sizeof(buf),
          "the bearings' errors, summed along each track, are larger than the bearing "
          "sigma of %s allows (variance x%.2f over %d tracks; %s): the sigmas "
          "reported include it (noise check). %s",
          bearing_noise_text(r.model.bearing_sigma, r.model.track_bias_sigma).c_str(),
          r.noise_check.check.scale,
          g,
          noise_check_chance(noise_check_limit(g, r.noise_check.level), "more", r.noise_check.level)
              .c_str(),
          remedy.c_str());
      out->emplace_back(buf);
    }
  }
}

// The wheel check shows a systematic wheel error.
void warn_wheel_error(const CalibrationResult& r, std::vector<std::string>* out) {
  char buf[1024];
  if (const WheelCheck& w = wheel_check_of(r); wheel_check_rejects_model(w)) {
    // The wheels' turns are (1 + s) x the robot's (eq. 15 divides by the wheel base: e (1 + s)
    // fits); c: rotation per metre rolled that the wheels report and the robot did not make
    // (right and left wheel scales |c| x e apart).
    std::string what;
    if (std::abs(w.rotation_scale) > 3.0 * w.sigma_rotation_scale) {
      std::snprintf(buf,
                    sizeof(buf),
                    "the wheels report turns %.2f%% %s than the robot made (+-%.2f%%; a wheel base "
                    "of %.4f m instead of %.4f m in wheel0/sensor.yaml would fit)",
                    100.0 * std::abs(w.rotation_scale),
                    w.rotation_scale > 0 ? "larger" : "smaller",
                    100.0 * w.sigma_rotation_scale,
                    w.wheel_base * (1.0 + w.rotation_scale),
                    w.wheel_base);
      what = buf;
    }
    if (std::abs(w.drift_per_m) > 3.0 * w.sigma_drift_per_m) {
      std::snprintf(buf,
                    sizeof(buf),
                    "%sthe wheels report %.3f deg of turning per metre rolled that the robot did "
                    "not make (+-%.3f; the right and left wheels' scales are about %.2f%% apart)",
                    what.empty() ? "" : "; ",
                    rad2deg(w.drift_per_m),
                    rad2deg(w.sigma_drift_per_m),
                    100.0 * std::abs(w.drift_per_m) * w.wheel_base);
      what += buf;
    }
    if (what.empty()) what = "the wheels' rotation disagrees with the bearings'";
    std::snprintf(buf,
                  sizeof(buf),
                  "wheel odometry has a systematic error that its model (eq. 31, K) does not "
                  "describe (wheel check chi-square %.1f, 99.9%% limit %.1f): %s. The extrinsics "
                  "may be biased by it: correct the wheel base and wheel scales in "
                  "wheel0/sensor.yaml, or raise --odometry-inflation (the paper used 5)",
                  w.chi2,
                  chi2_quantile(0.999, 2),
                  what.c_str());
    out->emplace_back(buf);
  }
}

// The refinement lies outside the filter's 99.9% ellipsoid.
void warn_disagreement(const CalibrationResult& r, std::vector<std::string>* out) {
  char buf[1024];
  if (r.refined && r.refinement.covariance_ok && r.filter.covariance.allFinite()) {
    const Extrinsics& f = r.filter.extrinsics;
    const Extrinsics& b = r.refinement.extrinsics;
    const Eigen::Vector3d d(wrap_angle(b.phi - f.phi), b.rho - f.rho, wrap_angle(b.psi - f.psi));
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(r.filter.covariance);
    const double m2 = ldlt.info() == Eigen::Success ? d.dot(ldlt.solve(d)) : 0.0;
    constexpr double kChi2_3_999 = 16.27;  // chi-square, 3 dof, 99.9%
    if (std::isfinite(m2) && m2 > kChi2_3_999) {
      std::snprintf(buf,
                    sizeof(buf),
                    "the filter and the refinement disagree (squared Mahalanobis distance %.1f "
                    "under the filter's covariance, 99.9%% limit %.1f; camera yaw %.3f vs %.3f "
                    "deg): the filter is biased or overconfident on this run and the "
                    "refinement's estimate is the one reported (tracks that slip onto a "
                    "neighbouring line do this; docs/theory/association.md)",
                    m2,
                    kChi2_3_999,
                    rad2deg(f.yaw()),
                    rad2deg(b.yaw()));
      out->emplace_back(buf);
    }
  }
}

}  // namespace

std::vector<std::string> result_warnings(const CalibrationResult& r) {
  std::vector<std::string> out;
  warn_gate_refusals(r, &out);
  warn_window_failure(r, &out);
  warn_more_noise(r, &out);
  warn_wheel_error(r, &out);
  warn_disagreement(r, &out);
  return out;
}

const WheelCheck& wheel_check_of(const CalibrationResult& r) {
  return r.refined ? r.refinement.noise.wheels : r.noise_check.filter_check.wheels;
}

}  // namespace omnivert::calib
