#include "omnivert/pipeline/calibration_report.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include <Eigen/Cholesky>
#include <nlohmann/json.hpp>

#include "calib/updater.hpp"  // chi2_quantile
#include "omnivert/core/angles.hpp"
#include "omnivert/pipeline/tilt_check.hpp"

namespace omnivert::pipeline {

ErrorsVsTruth errors_vs_truth(const calib::Extrinsics& est,
                              const Eigen::Matrix3d& C,
                              const calib::Extrinsics& truth) {
  ErrorsVsTruth e;
  e.phi = wrap_angle(est.phi - truth.phi);
  e.rho = est.rho - truth.rho;
  e.psi = wrap_angle(est.psi - truth.psi);
  const Eigen::Vector2d d = est.position() - truth.position();
  e.x = d(0);
  e.y = d(1);
  e.position = d.norm();
  e.yaw = wrap_angle(est.yaw() - truth.yaw());
  const Eigen::Vector3d v(e.phi, e.rho, e.psi);
  Eigen::LDLT<Eigen::Matrix3d> ldlt(C);
  if (C.allFinite() && ldlt.info() == Eigen::Success && ldlt.isPositive() &&
      ldlt.vectorD().minCoeff() > 0.0) {
    e.nees = v.dot(ldlt.solve(v));
  } else {
    e.nees = std::numeric_limits<double>::infinity();
  }
  return e;
}

namespace {

using nlohmann::json;

// A JSON number, or null when it is not finite (JSON has no NaN; we never write one).
json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json extrinsics_json(const calib::Extrinsics& e, const Eigen::Matrix3d& C) {
  json j;
  j["phi"] = num(e.phi), j["rho"] = num(e.rho), j["psi"] = num(e.psi);
  j["sigma_phi"] = num(std::sqrt(C(0, 0))), j["sigma_rho"] = num(std::sqrt(C(1, 1)));
  j["sigma_psi"] = num(std::sqrt(C(2, 2)));
  const Eigen::Vector2d p = e.position();
  j["x"] = num(p(0)), j["y"] = num(p(1)), j["yaw"] = num(e.yaw());
  json c = json::array();
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) c.push_back(num(C(i, k)));
  j["covariance"] = c;
  return j;
}

json errors_json(const ErrorsVsTruth& e) {
  return {{"phi_deg", num(rad2deg(e.phi))},
          {"rho_mm", num(e.rho * 1e3)},
          {"psi_deg", num(rad2deg(e.psi))},
          {"x_mm", num(e.x * 1e3)},
          {"y_mm", num(e.y * 1e3)},
          {"position_mm", num(e.position * 1e3)},
          {"yaw_deg", num(rad2deg(e.yaw))},
          {"nees", num(e.nees)}};
}

json verdict_json(const calib::ParameterVerdict& v) {
  return {{"determined", v.determined}, {"crlb", num(v.crlb)}};
}

std::string html_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&':
        o += "&amp;";
        break;
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '"':
        o += "&quot;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

std::string f(const char* format, double v) {
  if (!std::isfinite(v)) return "not determined";
  char b[64];
  std::snprintf(b, sizeof b, format, v);
  return b;
}

const char* verdict_name(calib::NoiseVerdict v) {
  switch (v) {
    case calib::NoiseVerdict::kMoreNoise:
      return "more noise";
    case calib::NoiseVerdict::kLessNoise:
      return "less noise";
    case calib::NoiseVerdict::kAgrees:
      break;
  }
  return "agrees";
}

}  // namespace

// Track splits as [{"track_id", "frame"}]: the tracker's id and the first frame of the new part.
nlohmann::json splits_json(const std::vector<calib::TrackSplit>& splits) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& [track, frame] : splits) a.push_back({{"track_id", track}, {"frame", frame}});
  return a;
}

// Pieces of one line joined as [{"track_id", "joined"}]: the earlier piece's id and the joined
// piece's.
nlohmann::json joins_json(const std::vector<calib::TrackJoin>& joins) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& [track, joined] : joins) a.push_back({{"track_id", track}, {"joined", joined}});
  return a;
}

std::string noise_check_line(const calib::CalibrationResult& r) {
  if (!r.noise_check.checked) return {};
  const int g = r.noise_check.check.clusters;
  char verdict[320] = "as the model allows: sigmas kept";
  if (r.noise_check.verdict == calib::NoiseVerdict::kMoreNoise)
    std::snprintf(verdict,
                  sizeof verdict,
                  "more than the model allows (%s): sigmas scaled by %.2f",
                  calib::noise_check_chance(
                      calib::noise_check_limit(g, r.noise_check.level), "more", r.noise_check.level)
                      .c_str(),
                  std::sqrt(r.noise_check.ratio));
  else if (r.noise_check.verdict == calib::NoiseVerdict::kLessNoise && r.noise_check.applied)
    std::snprintf(
        verdict,
        sizeof verdict,
        "less than the model assumes (%s): sigmas scaled by %.2f; %s would weight the "
        "bearings so from the start",
        calib::noise_check_chance(calib::noise_check_lower_limit(g, r.noise_check.lower_level),
                                  "less",
                                  r.noise_check.lower_level)
            .c_str(),
        std::sqrt(r.noise_check.ratio),
        calib::noise_check_flags(r).c_str());
  else if (r.noise_check.verdict == calib::NoiseVerdict::kLessNoise)
    std::snprintf(
        verdict,
        sizeof verdict,
        "less than the model assumes (%s): sigmas kept, on the safe side, as %zu pieces "
        "of lines were joined (pieces left apart hide noise from this check); %s would "
        "weight the bearings as the data say",
        calib::noise_check_chance(calib::noise_check_lower_limit(g, r.noise_check.lower_level),
                                  "less",
                                  r.noise_check.lower_level)
            .c_str(),
        r.source == calib::Estimator::kRefinement ? r.refinement.merges.size()
                                                  : r.filter.joins.size(),
        calib::noise_check_flags(r).c_str());
  char buf[640];
  std::snprintf(buf,
                sizeof(buf),
                "noise check over %d tracks: the errors along the tracks act as %s of "
                "%s (variance x%.2f; %s)",
                r.noise_check.check.clusters,
                calib::bearing_noise_text(calib::effective_bearing_sigma(r),
                                          calib::effective_track_bias_sigma(r))
                    .c_str(),
                r.model.track_bias_sigma > 0.0 ? "noise" : "independent noise",
                r.noise_check.check.scale,
                verdict);
  return buf;
}

std::string wheel_check_line(const calib::CalibrationResult& r) {
  const calib::WheelCheck& w = calib::wheel_check_of(r);
  if (!w.ok) return {};
  char buf[320];
  std::snprintf(buf,
                sizeof(buf),
                "wheel check over %d frames: the wheels' turns x%.4f (+-%.4f) of the robot's, "
                "%+.3f deg/m (+-%.3f) of drift; chi-square %.1f (99.9%% limit %.1f): %s",
                w.frames,
                1.0 + w.rotation_scale,
                w.sigma_rotation_scale,
                rad2deg(w.drift_per_m),
                rad2deg(w.sigma_drift_per_m),
                w.chi2,
                calib::chi2_quantile(0.999, 2),
                calib::wheel_check_rejects_model(w) ? "a systematic wheel error (see the warning)"
                                                    : "as the odometry model allows");
  return buf;
}

namespace {

json inputs_json(const calib::CalibrationResult& r, const ReportInputs& in) {
  json inputs;
  inputs["frames"] = in.frames;
  inputs["frames_skipped"] = in.frames_skipped;
  inputs["detections"] = in.detections;
  inputs["tracks_found"] = in.tracks_total;
  if (in.run) {
    inputs["tracks_used"] = in.run->tracks;
    inputs["bearings_used"] = in.run->observations;
    inputs["crowded_bearings"] = in.run->crowded_bearings;
    inputs["crowded_sigma_scale"] = num(in.run->crowded_sigma_scale);
    inputs["short_bearings_left_out"] = in.run->short_bearings;
    inputs["min_annulus_fraction"] = num(in.run->min_annulus_fraction);
    inputs["split_after_short"] = in.run->split_after_short;
    inputs["path_length_m"] = num(in.run->path_length);
    inputs["rotation_deg"] = num(rad2deg(in.run->rotation));
    inputs["frames_dropped_for_wheel_gaps"] = in.run->frames_dropped_for_gaps;
    inputs["frames_with_too_few_lines"] = in.run->starved_frames;
  }
  {
    const TiltEstimate& t = in.tilt;
    const bool given = in.tilt_rectified && !t.valid;
    inputs["tilt"] = {{"source",
                       t.valid ? "measured"
                       : given ? "given"
                               : "not measured"},
                      {"tilt_deg", t.valid || given ? num(t.tilt_deg()) : json(nullptr)},
                      {"direction_deg", t.valid || given ? num(t.direction_deg()) : json(nullptr)},
                      {"sigma_deg", t.valid ? num(rad2deg(t.sigma)) : json(nullptr)},
                      {"lines", t.lines},
                      {"frames", t.frames},
                      {"rectified", in.tilt_rectified}};
  }
  inputs["wheel_base_m"] = num(in.options.robot.wheel_base);
  inputs["odometry_K_m"] = num(in.options.robot.odometry_K);
  inputs["odometry_inflation"] = num(in.options.filter.odometry_inflation);
  inputs["bearing_sigma_deg"] = num(rad2deg(r.model.bearing_sigma));
  inputs["track_bias_sigma_deg"] = num(rad2deg(r.model.track_bias_sigma));

  inputs["prior"] = {{"phi", num(in.options.prior.mean.phi)},
                     {"rho", num(in.options.prior.mean.rho)},
                     {"psi", num(in.options.prior.mean.psi)},
                     {"sigma_phi", num(in.options.prior.sigma(0))},
                     {"sigma_rho", num(in.options.prior.sigma(1))},
                     {"sigma_psi", num(in.options.prior.sigma(2))},
                     {"source", in.prior_source.empty() ? "default" : in.prior_source}};
  return inputs;
}

json observability_json(const calib::ObservabilityReport& o) {
  return {{"observable", o.all_determined()},
          {"phi", verdict_json(o.phi)},
          {"rho", verdict_json(o.rho)},
          {"psi", verdict_json(o.psi)},
          {"yaw", verdict_json(o.yaw)},
          {"x", verdict_json(o.x)},
          {"y", verdict_json(o.y)},
          {"rank", o.rank},
          {"condition", num(o.condition)},
          {"heading_range_deg", num(rad2deg(o.heading_range))},
          {"heading_noise_deg", num(rad2deg(o.heading_noise))},
          {"message", o.message}};
}

json filter_json(const calib::FilterResult& f) {
  json j = extrinsics_json(f.extrinsics, f.covariance);
  // Tracks split in the filter's bootstrap window (they slipped onto a neighbouring line).
  j["tracks_split"] = f.splits.size();
  j["tracks_joined"] = f.joins.size();
  j["joins"] = joins_json(f.joins);
  j["window_frames"] = f.window_frames;
  j["window_solved"] = f.window_frames > 0 && f.window_failure.empty();
  if (!f.window_failure.empty()) j["window_failure"] = f.window_failure;
  j["splits"] = splits_json(f.splits);
  // Bearings left out where lines cross (CalibrationOptions::association.crossing_guard), window
  // and EKF.
  j["bearings_guarded"] = f.guarded.size();
  // Refused by the chi-square gate (outliers), window and EKF.
  j["bearings_rejected"] = f.rejected.size();
  return j;
}

json refinement_json(const calib::CalibrationResult& r) {
  json ref = extrinsics_json(r.refinement.extrinsics, r.refinement.covariance);
  ref["converged"] = r.refinement.converged;
  ref["covariance_ok"] = r.refinement.covariance_ok;
  ref["covariance_from_information"] = r.covariance_from_information;
  ref["iterations"] = r.refinement.iterations;
  ref["bearings_used"] = r.refinement.num_bearings;
  ref["bearings_rejected"] = r.refinement.num_rejected;
  ref["bearings_guarded"] = r.refinement.guarded.size();
  ref["tracks_split"] = r.refinement.num_splits;
  ref["features"] = r.refinement.num_features;
  ref["splits"] = splits_json(r.refinement.splits);
  ref["tracks_merged"] = r.refinement.merges.size();
  ref["merges"] = joins_json(r.refinement.merges);
  ref["bearing_residual_sigma_deg"] = num(rad2deg(r.refinement.bearing_residual_sigma));
  ref["initial_cost"] = num(r.refinement.initial_cost);
  ref["final_cost"] = num(r.refinement.final_cost);
  return ref;
}

json noise_check_json(const calib::CalibrationResult& r) {
  const calib::BatchNoiseCheck& n = r.noise_check.check;
  json nc;
  nc["checked"] = r.noise_check.checked;
  nc["applied"] = r.noise_check.applied;  // the reported covariance is the checked one
  nc["verdict"] = verdict_name(r.noise_check.verdict);
  // The levels of the verdict's sides (CalibrationOptions::noise_check.level, lower_level).
  nc["level_more_noise"] = r.noise_check.level;
  nc["level_less_noise"] = r.noise_check.lower_level;
  nc["scale"] = num(n.ok ? n.scale : NAN);
  nc["tracks"] = n.clusters;
  nc["effective_bearing_sigma_deg"] = num(rad2deg(calib::effective_bearing_sigma(r)));
  nc["effective_track_bias_sigma_deg"] = num(rad2deg(calib::effective_track_bias_sigma(r)));
  nc["variance_ratio"] =
      num(r.noise_check.checked ? r.noise_check.ratio : NAN);  // 1 when not applied
  nc["of"] = calib::estimator_name(r.source);
  nc["filter_scale"] = num(r.noise_check.filter_check.ok ? r.noise_check.filter_check.scale : NAN);
  nc["filter_variance_ratio"] =
      num(r.noise_check.filter_check.ok ? r.noise_check.filter_ratio : NAN);
  nc["filter_applied"] = r.noise_check.filter_applied;
  nc["filter_verdict"] = verdict_name(r.noise_check.filter_verdict);
  auto mat = [&](const Eigen::Matrix3d& m, bool ok) {
    json a = json::array();
    for (int i = 0; i < 9; ++i) a.push_back(num(ok && m.allFinite() ? m(i / 3, i % 3) : NAN));
    return a;
  };
  nc["filter_model_covariance"] = mat(r.noise_check.filter_model_covariance, true);
  nc["refinement_model_covariance"] = mat(r.noise_check.refinement_model_covariance, r.refined);
  nc["batch_model_covariance"] = mat(n.model_covariance, n.ok);
  nc["batch_checked_covariance"] = mat(n.covariance, n.ok);
  // The Cramer-Rao bounds at the noise the check found: each bound times the square root of
  // the checked over the model variance of that parameter.
  auto checked = [&](double crlb, int i) {
    return num(r.noise_check.checked
                   ? crlb * std::sqrt(n.covariance(i, i) / n.model_covariance(i, i))
                   : NAN);
  };
  {
    const calib::WheelCheck& w = calib::wheel_check_of(r);
    nc["wheels"] = {{"checked", w.ok},
                    {"frames", w.frames},
                    {"rotation_scale", num(w.ok ? w.rotation_scale : NAN)},
                    {"sigma_rotation_scale", num(w.ok ? w.sigma_rotation_scale : NAN)},
                    {"drift_deg_per_m", num(w.ok ? rad2deg(w.drift_per_m) : NAN)},
                    {"sigma_drift_deg_per_m", num(w.ok ? rad2deg(w.sigma_drift_per_m) : NAN)},
                    {"chi2", num(w.ok ? w.chi2 : NAN)},
                    {"rejects_model", calib::wheel_check_rejects_model(w)}};
  }
  nc["crlb_checked"] = {{"phi", checked(r.observability.phi.crlb, 0)},
                        {"rho", checked(r.observability.rho.crlb, 1)},
                        {"psi", checked(r.observability.psi.crlb, 2)}};
  return nc;
}

}  // namespace

std::string summary_json(const calib::CalibrationResult& r, const ReportInputs& in) {
  json j;
  j["tool"] = "omnivert calibrate";
  j["dataset"] = in.dataset;
  j["command"] = in.command;
  j["exit_code"] = in.exit_code;
  j["forced"] = in.force;
  j["wrote_extrinsics"] = in.wrote_extrinsics;
  j["inputs"] = inputs_json(r, in);
  j["observability"] = observability_json(r.observability);
  j["filter"] = filter_json(r.filter);
  if (r.refined) j["refinement"] = refinement_json(r);
  j["noise_check"] = noise_check_json(r);
  j["result"] = extrinsics_json(r.extrinsics, r.covariance);
  j["result"]["source"] = calib::estimator_name(r.source);
  if (in.truth) {
    j["ground_truth"] = {
        {"phi", num(in.truth->phi)}, {"rho", num(in.truth->rho)}, {"psi", num(in.truth->psi)}};
    json err;
    err["filter"] =
        errors_json(errors_vs_truth(r.filter.extrinsics, r.filter.covariance, *in.truth));
    if (r.source == calib::Estimator::kRefinement)
      err["refinement"] =
          errors_json(errors_vs_truth(r.refinement.extrinsics, r.refinement.covariance, *in.truth));
    j["errors_vs_ground_truth"] = err;
  }
  j["seconds"] = {{"tracking", num(in.seconds_tracking)},
                  {"calibration", num(in.seconds_calibration)}};
  {
    const auto& t = in.time_offset;
    j["time_offset_s"] = t.determined ? num(t.offset_s) : json(nullptr);
    j["time_offset_sigma_s"] = t.determined && !t.given ? num(t.sigma_s) : json(nullptr);
    j["time_offset"] = {{"source", t.given ? "given" : "estimated"},
                        {"determined", t.determined},
                        {"applied", t.applied},
                        {"pairs", t.pairs},
                        {"residual_scale", num(t.residual_scale)},
                        {"refined", t.refined},
                        {"from_tracks_s", t.refined ? num(t.tracks_offset_s) : json(nullptr)},
                        {"from_tracks_sigma_s", t.refined ? num(t.tracks_sigma_s) : json(nullptr)},
                        {"message", t.line}};
  }
  if (!in.reprojection_json.empty()) j["reprojection"] = json::parse(in.reprojection_json);
  if (!in.streaming_json.empty()) j["streaming"] = json::parse(in.streaming_json);
  j["warnings"] = in.warnings;
  return j.dump(2) + "\n";
}

namespace {

// The estimates (prior, filter, refinement, truth), the run's Cramer-Rao bounds, and the
// errors against the truth when known.
void html_estimates(std::ostringstream& h,
                    const calib::CalibrationResult& r,
                    const ReportInputs& in) {
  const calib::ObservabilityReport& o = r.observability;
  h << "<h2>Estimates</h2>\n<table><tr><th></th><th>phi [deg]</th><th>rho [mm]</th><th>psi "
       "[deg]</th>"
       "<th>camera x [mm]</th><th>camera y [mm]</th><th>camera yaw [deg]</th></tr>\n";
  auto row = [&](const std::string& name, const calib::Extrinsics& e, const Eigen::Matrix3d* C) {
    const Eigen::Vector2d p = e.position();
    h << "<tr><td>" << name << "</td><td>" << f("%.3f", rad2deg(e.phi));
    if (C) h << " &plusmn; " << f("%.3f", rad2deg(std::sqrt((*C)(0, 0))));
    h << "</td><td>" << f("%.2f", e.rho * 1e3);
    if (C) h << " &plusmn; " << f("%.2f", std::sqrt((*C)(1, 1)) * 1e3);
    h << "</td><td>" << f("%.3f", rad2deg(e.psi));
    if (C) h << " &plusmn; " << f("%.3f", rad2deg(std::sqrt((*C)(2, 2))));
    h << "</td><td>" << f("%.2f", p(0) * 1e3) << "</td><td>" << f("%.2f", p(1) * 1e3) << "</td><td>"
      << f("%.3f", rad2deg(e.yaw())) << "</td></tr>\n";
  };
  row(in.prior_source.empty() ? std::string("prior (default)")
                              : "prior (" + html_escape(in.prior_source) + ")",
      in.options.prior.mean,
      nullptr);
  row("filter (Sec. 8.2)", r.filter.extrinsics, &r.filter.covariance);
  if (r.source == calib::Estimator::kRefinement)
    row("batch refinement (--refine)", r.refinement.extrinsics, &r.refinement.covariance);
  if (in.truth) row("ground truth", *in.truth, nullptr);
  h << "</table>\n";
  h << "<table><tr><th>Cram&eacute;r-Rao bound (this run)</th><th>phi [deg]</th><th>rho [mm]</th>"
       "<th>psi [deg]</th><th>camera x [mm]</th><th>camera y [mm]</th><th>camera yaw "
       "[deg]</th></tr>\n"
    << "<tr><td>sigma</td><td>" << f("%.3f", rad2deg(o.phi.crlb)) << "</td><td>"
    << f("%.2f", o.rho.crlb * 1e3) << "</td><td>" << f("%.3f", rad2deg(o.psi.crlb)) << "</td><td>"
    << f("%.2f", o.x.crlb * 1e3) << "</td><td>" << f("%.2f", o.y.crlb * 1e3) << "</td><td>"
    << f("%.3f", rad2deg(o.yaw.crlb)) << "</td></tr></table>\n";
  if (in.truth) {
    h << "<table><tr><th>error vs ground truth</th><th>phi [deg]</th><th>rho [mm]</th><th>psi "
         "[deg]</th>"
         "<th>position [mm]</th><th>yaw [deg]</th><th>NEES (3 dof)</th></tr>\n";
    auto erow = [&](const std::string& name, const ErrorsVsTruth& e) {
      h << "<tr><td>" << name << "</td><td>" << f("%.3f", rad2deg(e.phi)) << "</td><td>"
        << f("%.2f", e.rho * 1e3) << "</td><td>" << f("%.3f", rad2deg(e.psi)) << "</td><td>"
        << f("%.2f", e.position * 1e3) << "</td><td>" << f("%.3f", rad2deg(e.yaw)) << "</td><td>"
        << f("%.2f", e.nees) << "</td></tr>\n";
    };
    erow("filter", errors_vs_truth(r.filter.extrinsics, r.filter.covariance, *in.truth));
    if (r.source == calib::Estimator::kRefinement)
      erow("refinement",
           errors_vs_truth(r.refinement.extrinsics, r.refinement.covariance, *in.truth));
    h << "</table>\n";
  }
}

// The run's inputs and what each stage did with them.
void html_inputs(std::ostringstream& h, const calib::CalibrationResult& r, const ReportInputs& in) {
  h << "<h2>Inputs</h2>\n<table>\n";
  auto kv = [&](const std::string& k, const std::string& v) {
    h << "<tr><td>" << k << "</td><td>" << html_escape(v) << "</td></tr>\n";
  };
  kv("images", std::to_string(in.frames) + " (" + std::to_string(in.frames_skipped) + " skipped)");
  kv("line detections / tracks",
     std::to_string(in.detections) + " / " + std::to_string(in.tracks_total));
  if (in.run) {
    kv("tracks / bearings used",
       std::to_string(in.run->tracks) + " / " + std::to_string(in.run->observations));
    kv("path driven / total rotation",
       f("%.2f m", in.run->path_length) + " / " + f("%.0f deg", rad2deg(in.run->rotation)));
    kv("bearings of crowded lines (sigma x)",
       std::to_string(in.run->crowded_bearings) + " (x" + f("%g", in.run->crowded_sigma_scale) +
           ")");
    kv("bearings of short lines left out (below)",
       std::to_string(in.run->short_bearings) + " (" + f("%g", in.run->min_annulus_fraction) +
           " of the annulus)");
    kv("frames with too few lines", std::to_string(in.run->starved_frames));
    kv("frames dropped for wheel gaps", std::to_string(in.run->frames_dropped_for_gaps));
  }
  if (!in.time_offset.line.empty()) kv("camera-odometry time offset", in.time_offset.line);
  {
    const std::string t = tilt_line(in.tilt, in.tilt_rectified);
    kv("tilt of the mirror axis", t.empty() ? std::string("not measured") : t);
  }
  kv("wheel base e / Chong-Kleeman K (x inflation)",
     f("%.4f m", in.options.robot.wheel_base) + " / " + f("%.3g m", in.options.robot.odometry_K) +
         " (x" + f("%g", in.options.filter.odometry_inflation) + ")");
  kv("bearing sigma", calib::bearing_noise_text(r.model.bearing_sigma, r.model.track_bias_sigma));
  kv("noise check", r.noise_check.checked ? noise_check_line(r) : std::string("not made"));
  {
    const std::string w = wheel_check_line(r);
    kv("wheel check", w.empty() ? std::string("not made") : w);
  }
  kv("filter's window",
     r.filter.window_frames == 0
         ? std::string("none")
         : std::to_string(r.filter.window_frames) + " frames solved as a batch" +
               (r.filter.window_failure.empty()
                    ? ", " + std::to_string(r.filter.splits.size()) +
                          " tracks split where they changed line; " +
                          std::to_string(r.filter.guarded.size()) +
                          " bearings left out where lines cross (window and filter); " +
                          std::to_string(r.filter.joins.size()) +
                          " tracks joined to the line they continue (window and filter)"
                    : std::string(": could not be solved (") + r.filter.window_failure +
                          "), the filter ran over it from the prior"));
  if (r.refined)
    kv("refinement",
       std::string(r.refinement.converged ? "converged" : "did not converge") + ", " +
           std::to_string(r.refinement.iterations) + " iterations, " +
           std::to_string(r.refinement.num_bearings) + " bearings (" +
           std::to_string(r.refinement.num_rejected) + " rejected as outliers, " +
           std::to_string(r.refinement.guarded.size()) + " left out where lines cross), " +
           std::to_string(r.refinement.num_splits) + " tracks split where they " +
           "changed line, " + std::to_string(r.refinement.merges.size()) +
           " joined to the line they continue");
  kv("time: tracking / calibration",
     f("%.1f s", in.seconds_tracking) + " / " + f("%.1f s", in.seconds_calibration));
  h << "</table>\n";
}

}  // namespace

std::string report_html(const calib::CalibrationResult& r, const ReportInputs& in) {
  std::ostringstream h;
  const calib::ObservabilityReport& o = r.observability;
  h << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>omnivert calibrate: "
    << html_escape(in.dataset)
    << "</title>\n<style>body{font-family:sans-serif;max-width:1700px;"
       "margin:1em auto;padding:0 1em}table{border-collapse:collapse;margin:0.5em 0}"
       "td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}th{background:#eee}"
       "td:first-child,th:first-child{text-align:left}.ok{color:#060}.bad{color:#a00}"
       "img{max-width:100%;border:1px solid #ccc}</style></head><body>\n";
  h << "<h1>Camera-to-odometry calibration</h1>\n";
  h << "<p>Dataset <code>" << html_escape(in.dataset) << "</code>; command <code>"
    << html_escape(in.command) << "</code>.</p>\n";
  const bool obs = o.all_determined();
  h << "<h2>Verdict</h2>\n<p class=\"" << (obs ? "ok" : "bad") << "\"><b>"
    << (obs ? "Determined." : "Not determined.") << "</b> " << html_escape(o.message) << "</p>\n";
  if (!obs)
    h << "<p>"
      << (in.force ? "--force was given: extrinsics.yaml was written anyway."
                   : "extrinsics.yaml was not written (exit code 3); --force writes it.")
      << "</p>\n";

  html_estimates(h, r, in);
  html_inputs(h, r, in);
  if (!in.warnings.empty()) {
    h << "<h2>Warnings</h2>\n<ul>\n";
    for (const auto& w : in.warnings) h << "<li>" << html_escape(w) << "</li>\n";
    h << "</ul>\n";
  }
  h << "<h2>Convergence (the paper's Fig. 25)</h2>\n<img src=\"convergence.png\" "
       "alt=\"phi, rho, psi and their sigmas against the frame\">\n";
  h << "<h2>Tracks (the paper's Fig. 22)</h2>\n<img src=\"tracks.png\" alt=\"bearing of every "
       "tracked line against the frame\">\n";
  h << in.reprojection_html;
  h << in.streaming_html;
  h << "<p>Files: extrinsics.yaml, states.csv, tracks.csv, summary.json.</p>\n</body></html>\n";
  return h.str();
}

}  // namespace omnivert::pipeline
