// CalibrationResult::BriefReport and FullReport: the result as text for a terminal.

#include <cmath>
#include <cstdio>
#include <string>

#include "omnivert/calib/calibrate.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

namespace {

std::string format(const char* fmt, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

// "phi 12.345 +- 0.067 deg, rho 201.23 +- 0.45 mm, psi -3.210 +- 0.070 deg"
std::string estimate_text(const Extrinsics& e, const Eigen::Matrix3d& C) {
  return format("phi %.3f +- %.3f deg, rho %.2f +- %.2f mm, psi %.3f +- %.3f deg",
                rad2deg(e.phi),
                rad2deg(std::sqrt(C(0, 0))),
                e.rho * 1e3,
                std::sqrt(C(1, 1)) * 1e3,
                rad2deg(e.psi),
                rad2deg(std::sqrt(C(2, 2))));
}

const char* verdict_text(NoiseVerdict v) {
  switch (v) {
    case NoiseVerdict::kMoreNoise:
      return "more noise than the model allows";
    case NoiseVerdict::kLessNoise:
      return "less noise than the model assumes";
    case NoiseVerdict::kAgrees:
      break;
  }
  return "agrees with the model";
}

std::string noise_check_text(const CalibrationResult& r) {
  const NoiseCheckReport& n = r.noise_check;
  if (!n.checked) return "noise check: not made\n";
  std::string s = format("noise check: over %d tracks, scale %.3f: %s (levels %g / %g)",
                         n.check.clusters,
                         n.check.scale,
                         verdict_text(n.verdict),
                         n.level,
                         n.lower_level);
  s += n.applied ? format("; applied, variance ratio %.3f\n", n.ratio) : "; not applied\n";
  s += "  bearing noise the errors act as: " +
       bearing_noise_text(effective_bearing_sigma(r), effective_track_bias_sigma(r)) + "\n";
  if (n.filter_check.ok)
    s += format("  filter's own check: scale %.3f over %d tracks: %s%s\n",
                n.filter_check.scale,
                n.filter_check.clusters,
                verdict_text(n.filter_verdict),
                n.filter_applied ? format(", applied (ratio %.3f)", n.filter_ratio).c_str() : "");
  return s;
}

std::string association_text(const CalibrationResult& r) {
  const FilterResult& f = r.filter;
  std::string s = format(
      "filter: start-up window %d frames%s; %zu tracks split, %zu joined, %zu bearings guarded, "
      "%zu rejected\n",
      f.window_frames,
      f.window_failure.empty() ? "" : (" (not solved: " + f.window_failure + ")").c_str(),
      f.splits.size(),
      f.joins.size(),
      f.guarded.size(),
      f.rejected.size());
  if (!r.refined) return s;
  const RefinementResult& q = r.refinement;
  s += format(
      "refinement: %s after %d iterations (cost %.6g -> %.6g); %d bearings, %d features; %d "
      "tracks split, %zu joined, %zu bearings guarded, %zu rejected; residual sigma %.4f deg\n",
      q.converged ? "converged" : "not converged",
      q.iterations,
      q.initial_cost,
      q.final_cost,
      q.num_bearings,
      q.num_features,
      q.num_splits,
      q.merges.size(),
      q.guarded.size(),
      q.rejected.size(),
      rad2deg(q.bearing_residual_sigma));
  return s;
}

}  // namespace

std::string CalibrationResult::BriefReport() const {
  const bool from_refinement = source == Estimator::kRefinement;
  std::string s = (from_refinement ? "refined estimate: " : "filter estimate: ") +
                  estimate_text(extrinsics, covariance) + "\n";
  const Eigen::Vector2d p = extrinsics.position();
  s += format("camera in the robot frame: x %.2f mm, y %.2f mm, yaw %.3f deg\n",
              p(0) * 1e3,
              p(1) * 1e3,
              rad2deg(extrinsics.yaw()));
  s += observability.message + "\n";
  return s;
}

std::string CalibrationResult::FullReport() const {
  std::string s = BriefReport();
  s += "filter: " + estimate_text(filter.extrinsics, filter.covariance) + "\n";
  s += "  model covariance: " +
       estimate_text(filter.extrinsics, noise_check.filter_model_covariance) + "\n";
  if (refined) {
    s += "refinement: " + estimate_text(refinement.extrinsics, refinement.covariance) +
         (refinement.covariance_ok ? "" : " (no covariance)") +
         (covariance_from_information ? " (covariance from the Fisher information)" : "") + "\n";
    s += "  model covariance: " +
         estimate_text(refinement.extrinsics, noise_check.refinement_model_covariance) + "\n";
  }
  const ObservabilityReport& o = observability;
  s += format(
      "Cramer-Rao bound: phi %.3f deg, rho %.2f mm, psi %.3f deg, yaw %.3f deg; rank %d, "
      "condition %.3g; heading range %.1f deg (odometry noise %.3f deg)\n",
      rad2deg(o.phi.crlb),
      o.rho.crlb * 1e3,
      rad2deg(o.psi.crlb),
      rad2deg(o.yaw.crlb),
      o.rank,
      o.condition,
      rad2deg(o.heading_range),
      rad2deg(o.heading_noise));
  s += "bearing noise model: " + bearing_noise_text(model.bearing_sigma, model.track_bias_sigma) +
       "\n";
  s += noise_check_text(*this);
  const WheelCheck& w = wheel_check_of(*this);
  if (w.ok)
    s += format(
        "wheel check: rotation scale %+.4f +- %.4f, drift %+.5f +- %.5f rad/m, chi-square %.2f "
        "over %d frames\n",
        w.rotation_scale,
        w.sigma_rotation_scale,
        w.drift_per_m,
        w.sigma_drift_per_m,
        w.chi2,
        w.frames);
  s += association_text(*this);
  s += format("time: filter %.2f s, refinement %.2f s, observability %.2f s, noise check %.2f s\n",
              seconds.filter,
              seconds.refinement,
              seconds.observability,
              seconds.noise_check);
  for (const std::string& w : result_warnings(*this)) s += "warning: " + w + "\n";
  return s;
}

}  // namespace omnivert::calib
