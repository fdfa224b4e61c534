#include "omnivert/pipeline/calibrate_dataset.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include <spdlog/spdlog.h>

#include "omnivert/calib/calibrate.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/core/file_io.hpp"
#include "omnivert/image/image_io.hpp"
#include "omnivert/pipeline/calibration_report.hpp"
#include "omnivert/viz/convergence_plot.hpp"
#include "omnivert/viz/tracks_plot.hpp"
#include "pipeline/streaming_run.hpp"

namespace omnivert::pipeline {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

// Fewer tracks than this: the estimate rests on few features. Measured on the simulator's
// office (docs/theory/association.md): about 10 tracks at the paper's 50% length gave a median
// camera yaw error of 0.14-0.17 degree over 50 runs; 25% lines with the refinement 0.006.
constexpr int kFewTracks = 15;

// The output files of a run; those of an earlier run are removed first, so that none of them
// passes for this run's.
constexpr const char* kOutputs[] = {"extrinsics.yaml",
                                    "summary.json",
                                    "report.html",
                                    "states.csv",
                                    "convergence.png",
                                    "tracks.csv",
                                    "tracks.png",
                                    calib::kRobotFormatFiles[0],
                                    calib::kRobotFormatFiles[1],
                                    calib::kRobotFormatFiles[2],
                                    "reprojection.png",
                                    "streaming.csv"};

std::string few_tracks_warning(int tracks,
                               const FeaturePipelineOptions& features,
                               double used_fraction) {
  std::string w = "only " + std::to_string(tracks) +
                  " lines were tracked: the estimate rests on few features and may be off by "
                  "more than its sigma";
  if (used_fraction > 0.3)
    w += "; shorter lines help (--calibration-length-fraction 0.25 with --refine; "
         "docs/calibration.md, \"Warnings\")";
  else if (features.lines.threshold == LineThreshold::kFractionOfAnnulus &&
           features.lines.length_fraction > 0.3)
    w += "; shorter lines help (the default --line-threshold significance)";
  return w;
}

// Step 1: the tracks, of the images or of an earlier tracks.csv.
TrackDatasetResult tracks_of(const dataset::Dataset& data,
                             const CalibrateDatasetOptions& o,
                             std::optional<TrackDatasetResult> given,
                             const std::string& stage = "track") {
  if (given) return std::move(*given);
  TrackDatasetOptions to;
  to.pipeline = o.features;
  to.mask = o.mask;
  to.tracker = o.tracker;
  to.tilt = o.tilt;
  to.threads = o.threads;
  return track_dataset(data, to, [&](std::size_t done, std::size_t total) {
    if (o.progress) o.progress(stage, done, total);
  });
}

// Shifts the image stamps by the time offset (Dataset::set_image_time_offset); the images
// whose odometry time then falls outside the wheel data are warned about (their bearings are
// not used: calibration_run_from_tracks).
void apply_time_offset(dataset::Dataset& data,
                       double offset_s,
                       bool given,
                       CalibrateDatasetResult& r) {
  const int outside = data.set_image_time_offset(std::llround(offset_s * 1e9));
  if (given) {
    r.time_offset_given = true;
    r.time_offset.determined = true;
    r.time_offset.offset_s = offset_s;
  }
  r.time_offset_applied = offset_s != 0.0;
  if (outside > 0)
    r.warnings.push_back(std::to_string(outside) + " images fall outside the wheel data once " +
                         "their stamps are shifted by the time offset (" +
                         std::to_string(offset_s * 1e3) + " ms); their bearings are not used");
}

// The refinement's estimate of the time offset (calib::RefinementOptions::estimate_time_offset)
// in place of the tracks': the offset applied before tracking plus the refinement's
// correction, with the refinement's sigma (not determined above options.max_sigma_s).
void refined_time_offset(const calib::RefinementResult& ref,
                         const TimeOffsetOptions& options,
                         CalibrateDatasetResult& r) {
  if (!ref.time_offset_estimated || !std::isfinite(ref.time_offset_sigma_s)) return;
  TimeOffsetEstimate& e = r.time_offset;
  if (!e.refined) {  // a second refinement (time_offset_from_refinement) keeps the tracks'
    e.tracks_offset_s = e.offset_s;
    e.tracks_sigma_s = e.sigma_s;
  }
  e.refined = true;
  e.offset_s = (r.time_offset_applied ? e.offset_s : 0.0) + ref.time_offset_s;
  e.sigma_s = ref.time_offset_sigma_s;
  e.determined = e.sigma_s <= options.max_sigma_s;
  if (!e.determined) e.why = "the refinement leaves it undetermined";
}

ReportInputs::TimeOffset time_offset_report(const CalibrateDatasetResult& r) {
  ReportInputs::TimeOffset t;
  const TimeOffsetEstimate& e = r.time_offset;
  t.given = r.time_offset_given;
  t.determined = e.determined;
  t.applied = r.time_offset_applied;
  t.offset_s = e.offset_s;
  t.sigma_s = e.sigma_s;
  t.pairs = e.pairs;
  t.residual_scale = e.residual_scale;
  t.refined = e.refined;
  t.tracks_offset_s = e.tracks_offset_s;
  t.tracks_sigma_s = e.tracks_sigma_s;
  t.line = r.time_offset_message;
  return t;
}

// The check by eye (pipeline/reprojection.hpp): the reference's corners against the tracked
// lines, with the prior and with the estimate; reprojection.png and the report's section.
// A laser0/ found (not asked for) that cannot be used is a warning.
void reprojection_check(const dataset::Dataset& data,
                        const std::vector<TrackRow>& rows,
                        const calib::Extrinsics& before,
                        const calib::Extrinsics& after,
                        const CalibrateDatasetOptions& o,
                        ReportInputs& ri,
                        CalibrateDatasetResult& r) {
  ReprojectionOptions ro = o.reprojection;
  ro.features = o.features;
  ro.mask = o.mask;
  if (!o.check_reference) {
    std::error_code ec;
    if (o.check_off || !fs::is_directory(fs::path(data.root()) / "laser0", ec)) return;
    ro.reference.source = ReferenceSource::kLaser;
  }
  try {
    const References refs = load_references(data, ro.reference);
    std::vector<std::vector<double>> lines(data.size());
    for (const TrackRow& row : rows)
      if (row.frame >= 0 && static_cast<std::size_t>(row.frame) < lines.size())
        lines[static_cast<std::size_t>(row.frame)].push_back(row.bearing);
    const ReprojectionResult c = check_reprojection(data, refs, lines, before, after, ro);
    write_image_atomic((fs::path(r.out_dir) / "reprojection.png").string(), c.picture);
    ri.reprojection_json = c.json();
    ri.reprojection_html = c.html("reprojection.png");
    r.reprojection_message = c.message();
  } catch (const InputError& e) {
    if (o.check_reference) throw;
    r.warnings.push_back(std::string("the check by eye against laser0/ was not made: ") + e.what());
    spdlog::warn("{}", r.warnings.back());
    ri.warnings = r.warnings;
  }
}

void prepare_out_dir(const std::string& out_dir) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw InputError(out_dir, 0, "cannot create the output folder: " + ec.message());
  for (const char* f : kOutputs) fs::remove(fs::path(out_dir) / f, ec);
}

}  // namespace

bool CalibrateDatasetOptions::IsValid(std::string* why) const {
  std::string w;
  const auto fail = [&](const char* group) {
    if (why) *why = std::string(group) + " options: " + w;
    return false;
  };
  if (!features.IsValid(&w)) return fail("extraction");
  if (!frames.IsValid(&w)) return fail("frame");
  TrackerOptions t = tracker;
  if (t.gate.enabled && t.gate.wheel_base == 0.0) t.gate.wheel_base = 1.0;  // from wheel0/
  if (!t.IsValid(&w)) return fail("tracker");
  if (!tilt.IsValid(&w)) return fail("tilt");
  if (!calibration.IsValid(&w)) return fail("calibration");
  if (!input.IsValid(&w)) return fail("input");
  if (!time_offset.IsValid(&w)) return fail("time offset");
  if (streaming && !tracks_file.empty()) {
    w = "streaming needs the images, not an earlier tracks file";
    return fail("input");
  }
  if (streaming && calibration.refinement.enabled) {
    w = "streaming gives the filter's estimate; the refinement needs the whole run";
    return fail("calibration");
  }
  if (time_offset_s && !std::isfinite(*time_offset_s)) {
    w = "time_offset_s must be finite [s]";
    return fail("time offset");
  }
  return true;
}

namespace {

// The dataset and the checks made before any work (bad input, exit code 2); *opt: the
// calibration options with the dataset's wheel base and K.
dataset::Dataset load_checked(const std::string& dataset_dir,
                              const CalibrateDatasetOptions& o,
                              calib::CalibrationOptions* opt) {
  std::string why;
  if (!o.IsValid(&why)) throw InputError("invalid " + why);
  dataset::LoadOptions lo;
  lo.require_wheel = true;
  lo.allow_missing_images = true;
  // The ground truth's lines only for the check against the simulator's map.
  lo.ground_truth_lines =
      o.check_reference && !o.check_off && o.reprojection.reference.source == ReferenceSource::kMap;
  auto data = dataset::Dataset::load(dataset_dir, lo);
  for (const std::string& n : data.notes()) spdlog::debug("{}", n);
  // Ground truth is optional here (the report's truth rows): one that cannot be read is a
  // warning, not a reason to refuse the calibration.
  if (!data.ground_truth_error().empty())
    spdlog::warn("ground truth not used: {}", data.ground_truth_error());
  *opt = options_from_dataset(data, o.calibration);
  opt->threads = o.threads;  // --threads: the estimators' too
  if (!opt->IsValid(&why)) throw InputError("invalid calibration options: " + why);
  if (!o.reprojection.IsValid(&why)) throw InputError("invalid check options: " + why);
  // A reference asked for is checked before the work (bad input, exit code 2).
  if (o.check_reference && !o.check_off) (void)load_references(data, o.reprojection.reference);
  return data;
}

// The time offset, estimated from the tracks when not given. Applied, it also changes the
// wheel travel between frames that the tracker's odometry gate predicts with (Sec. 9.1), so
// the images are tracked again on the corrected stamps.
void time_offset_from_tracks(dataset::Dataset& data,
                             const CalibrateDatasetOptions& o,
                             const calib::CalibrationOptions& opt,
                             bool from_images,
                             TrackDatasetResult& tracked,
                             CalibrateDatasetResult& r) {
  if (o.time_offset_s) return;
  if (o.streaming) {
    r.time_offset.why = "not estimated when streaming";
    return;
  }
  TimeOffsetOptions offset = o.time_offset;
  offset.threads = o.threads;  // --threads: the grid's evaluation too
  r.time_offset = estimate_time_offset(
      data, tracked.rows, opt.robot.odometry_K, opt.noise.bearing_sigma, offset);
  if (r.time_offset.significant(o.time_offset)) {
    apply_time_offset(data, r.time_offset.offset_s, false, r);
    if (from_images) tracked = tracks_of(data, o, std::nullopt, "track again");
  }
}

// Steps 2-3 on the tracks: the calibration's input, then filter, observability and refinement
// (Sec. 8), with the time offset's correction estimated by the refinement from the offset
// applied (or none) when the tracks determined it: the tracks' estimate is the first order of
// a model whose coefficients change where the motion changes; the refinement's is the whole
// model's.
// Returns the seconds it took.
double calibrate_tracks(const dataset::Dataset& data,
                        const TrackDatasetResult& tracked,
                        std::optional<internal::StreamedRun>& streamed,
                        const CalibrateDatasetOptions& o,
                        calib::CalibrationOptions opt,
                        CalibrateDatasetResult& r) {
  const auto t0 = Clock::now();
  r.warnings.insert(r.warnings.begin(), tracked.warnings.begin(), tracked.warnings.end());
  r.input = streamed ? std::move(streamed->input)
                     : calibration_run_from_tracks(data, tracked.rows, o.input);
  r.warnings.insert(r.warnings.end(), r.input.warnings.begin(), r.input.warnings.end());
  if (r.input.tracks < kFewTracks)
    r.warnings.push_back(
        few_tracks_warning(r.input.tracks, o.features, r.input.min_annulus_fraction));
  r.warnings.insert(r.warnings.end(), o.notes.begin(), o.notes.end());
  for (const auto& w : r.warnings) spdlog::warn("{}", w);
  const bool refine_offset =
      !o.time_offset_s && !streamed && opt.refinement.enabled && r.time_offset.determined;
  if (refine_offset) {
    r.input.run.clock = wheel_clock(data);
    opt.refinement.estimate_time_offset = true;
  }
  if (o.progress) {
    o.progress("calibrate", 0, 0);
    opt.progress = [&o](const std::string& stage, std::size_t done, std::size_t total) {
      o.progress(stage, done, total);
    };
  }
  r.calibration = streamed ? calib::result_of_filter(r.input.run, opt, std::move(streamed->filter))
                           : calib::calibrate(r.input.run, opt);
  if (refine_offset) refined_time_offset(r.calibration.refinement, o.time_offset, r);
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The refinement's correction of the offset the images were tracked with, when significant
// (|dS| above TimeOffsetOptions::significance sigmas and min_applied_s: the tracks' estimate
// was left unapplied, its sigma covering a single change of motion, or was off): the total is
// applied and the images tracked again, once, the warnings back to those before the
// calibration; true when the run is to be calibrated again.
bool time_offset_from_refinement(dataset::Dataset& data,
                                 const CalibrateDatasetOptions& o,
                                 bool from_images,
                                 TrackDatasetResult& tracked,
                                 const std::vector<std::string>& warnings_before,
                                 CalibrateDatasetResult& r) {
  TimeOffsetEstimate& e = r.time_offset;
  const calib::RefinementResult& ref = r.calibration.refinement;
  if (!e.refined || !e.determined || e.retracked) return false;
  if (!o.time_offset.significant(ref.time_offset_s, ref.time_offset_sigma_s)) return false;
  e.retracked = true;
  e.retracked_s = e.offset_s;
  e.tracks_applied = r.time_offset_applied;
  r.warnings = warnings_before;
  apply_time_offset(data, e.offset_s, false, r);
  if (from_images) tracked = tracks_of(data, o, std::nullopt, "track again");
  return true;
}

}  // namespace

CalibrateDatasetResult calibrate_dataset(const std::string& dataset_dir,
                                         const std::string& out_dir,
                                         const CalibrateDatasetOptions& o) {
  calib::CalibrationOptions opt;
  auto data = load_checked(dataset_dir, o, &opt);

  // Read before the output folder is cleared: the tracks file may be out_dir/tracks.csv.
  std::optional<TrackDatasetResult> given;
  if (!o.tracks_file.empty()) given = read_tracks_for_dataset(o.tracks_file, data);
  prepare_out_dir(out_dir);
  const fs::path out(out_dir);

  CalibrateDatasetResult r;
  r.out_dir = out_dir;
  r.noise_check_requested = o.calibration.noise_check.enabled && !o.streaming;
  const auto t0 = Clock::now();
  if (o.time_offset_s) apply_time_offset(data, *o.time_offset_s, true, r);  // before tracking
  const bool from_images = !given.has_value();
  std::optional<internal::StreamedRun> streamed;
  if (o.streaming) streamed = internal::stream_dataset(data, o, opt);
  TrackDatasetResult tracked =
      streamed ? std::move(streamed->tracked) : tracks_of(data, o, std::move(given));

  time_offset_from_tracks(data, o, opt, from_images, tracked, r);
  const std::vector<std::string> warnings_before = r.warnings;
  double calibrating_s = calibrate_tracks(data, tracked, streamed, o, opt, r);
  if (time_offset_from_refinement(data, o, from_images, tracked, warnings_before, r))
    calibrating_s += calibrate_tracks(data, tracked, streamed, o, opt, r);
  r.tilt = tracked.tilt;
  r.tilt_corrected = tracked.tilt_corrected;
  write_tracks_csv(out / "tracks.csv", tracked.rows);
  viz::write_tracks_png(out / "tracks.png", tracked.rows);
  r.frames = tracked.frames;
  r.frames_skipped = tracked.frames_skipped;
  r.detections = static_cast<std::int64_t>(tracked.rows.size());
  const auto t2 = Clock::now();
  const calib::CalibrationResult& result = r.calibration;
  if (!result.extrinsics.vec().allFinite() || !result.covariance.allFinite())
    throw std::runtime_error(
        "the calibration diverged (non-finite estimate); nothing written but tracks.csv. Check "
        "the wheel base and K in wheel0/sensor.yaml and the tracks in tracks.png");
  for (const std::string& w : calib::result_warnings(result)) {
    spdlog::warn("{}", w);
    r.warnings.push_back(w);
  }
  r.wrote_extrinsics = result.observable() || o.force;
  if (data.ground_truth() && data.ground_truth()->extrinsics) {
    const auto& g = *data.ground_truth()->extrinsics;
    r.truth = calib::Extrinsics{g.phi, g.rho, g.psi};
  }

  // Step 4: the outputs, each written to a temporary name and renamed.
  calib::write_states_csv((out / "states.csv").string(), result.filter.history);
  std::optional<calib::Extrinsics> refined;
  if (result.source == calib::Estimator::kRefinement) refined = result.refinement.extrinsics;
  write_image_atomic((out / "convergence.png").string(),
                     viz::draw_convergence(result.filter.history, r.truth, refined));
  ReportInputs ri;
  ri.dataset = o.input_name.empty() ? dataset_dir : o.input_name;
  ri.prior_source = o.prior_source;
  ri.command = o.command;
  ri.frames = tracked.frames;
  ri.frames_skipped = tracked.frames_skipped;
  ri.detections = r.detections;
  ri.tracks_total = tracked.stats.new_tracks;
  ri.run = &r.input;
  ri.options = opt;
  ri.options.noise.bearing_sigma = result.model.bearing_sigma;
  ri.truth = r.truth;
  ri.force = o.force;
  ri.exit_code = r.wrote_extrinsics ? 0 : 3;
  ri.seconds_tracking = std::chrono::duration<double>(t2 - t0).count() - calibrating_s;
  ri.seconds_calibration = calibrating_s;
  ri.warnings = r.warnings;
  ri.wrote_extrinsics = r.wrote_extrinsics;
  r.time_offset_message =
      time_offset_line(r.time_offset, r.time_offset_given, r.time_offset_applied, o.time_offset);
  ri.time_offset = time_offset_report(r);
  ri.tilt = r.tilt;
  ri.tilt_rectified = r.tilt_corrected;
  reprojection_check(data, tracked.rows, opt.prior.mean, result.extrinsics, o, ri, r);
  if (streamed) {
    internal::write_streaming_csv((out / "streaming.csv").string(), streamed->estimates);
    ri.streaming_json = internal::streaming_json(streamed->estimates);
    ri.streaming_html = internal::streaming_html(streamed->estimates);
    r.streaming_message = internal::streaming_line(streamed->estimates);
  }
  if (r.wrote_extrinsics) {
    calib::write_extrinsics_yaml((out / "extrinsics.yaml").string(), result);
    calib::write_robot_formats(out.string(), result.extrinsics, result.covariance, o.frames);
  }
  write_text_atomic((out / "summary.json").string(), summary_json(result, ri));
  write_text_atomic((out / "report.html").string(), report_html(result, ri));
  return r;
}

namespace {

std::string format(const char* fmt, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

std::string truth_lines(const CalibrateDatasetResult& r, bool refined) {
  std::string s;
  auto show = [&](const char* name, const calib::Extrinsics& est, const Eigen::Matrix3d& cov) {
    const auto er = errors_vs_truth(est, cov, *r.truth);
    s += format(
        "error vs ground truth (%s): phi %.3f deg, rho %.2f mm, psi %.3f deg, "
        "position %.2f mm, yaw %.3f deg, NEES %.2f\n",
        name,
        rad2deg(er.phi),
        er.rho * 1e3,
        rad2deg(er.psi),
        er.position * 1e3,
        rad2deg(er.yaw),
        er.nees);
  };
  const auto& c = r.calibration;
  show("filter", c.filter.extrinsics, c.filter.covariance);
  if (refined) show("refinement", c.refinement.extrinsics, c.refinement.covariance);
  return s;
}

}  // namespace

std::string CalibrateDatasetResult::BriefReport() const {
  const calib::CalibrationResult& c = calibration;
  const bool refined = c.source == calib::Estimator::kRefinement;
  const auto& e = c.extrinsics;
  const auto& C = c.covariance;
  const auto& o = c.observability;
  std::string s = format(
      "%lld frames (%lld skipped), %lld detections, %d tracks used, %d bearings; "
      "%.2f m driven, %.0f deg turned\n",
      static_cast<long long>(frames),
      static_cast<long long>(frames_skipped),
      static_cast<long long>(detections),
      input.tracks,
      input.observations,
      input.path_length,
      rad2deg(input.rotation));
  s += format("%s estimate:  phi %.3f +- %.3f deg   rho %.2f +- %.2f mm   psi %.3f +- %.3f deg\n",
              refined ? "refined" : "filter",
              rad2deg(e.phi),
              rad2deg(std::sqrt(C(0, 0))),
              e.rho * 1e3,
              std::sqrt(C(1, 1)) * 1e3,
              rad2deg(e.psi),
              rad2deg(std::sqrt(C(2, 2))));
  const Eigen::Vector2d p = e.position();
  s += format("camera in the robot frame: x %.2f mm, y %.2f mm, yaw %.3f deg\n",
              p(0) * 1e3,
              p(1) * 1e3,
              rad2deg(e.yaw()));
  const std::string noise =
      calib::bearing_noise_text(c.model.bearing_sigma, c.model.track_bias_sigma);
  if (c.noise_check.checked)
    s += "bearing sigma " + noise + "; " + noise_check_line(c) + "\n";
  else
    s += "bearing sigma " + noise + " (no noise check" +
         (noise_check_requested ? ": the run does not determine the extrinsics" : "") + ")\n";
  if (const std::string w = wheel_check_line(c); !w.empty()) s += w + "\n";
  if (c.refined && c.refinement.num_splits > 0)
    s += format("refinement: %d tracks split where they changed line (summary.json lists them)\n",
                c.refinement.num_splits);
  if (!c.filter.joins.empty())
    s += format("filter: %zu tracks joined to the line they continue after the tracker lost it\n",
                c.filter.joins.size());
  if (c.refined && !c.refinement.merges.empty())
    s += format(
        "refinement: %zu tracks joined to the line they continue after the tracker lost "
        "it (summary.json lists them)\n",
        c.refinement.merges.size());
  s += format("Cramer-Rao bound of this run: phi %.3f deg, rho %.2f mm, psi %.3f deg\n",
              rad2deg(o.phi.crlb),
              o.rho.crlb * 1e3,
              rad2deg(o.psi.crlb));
  s += time_offset_message + "\n";
  if (!reprojection_message.empty()) s += reprojection_message + "\n";
  if (truth) s += truth_lines(*this, refined);
  s += o.message + "\n";
  s += "results in " + out_dir + ": " +
       (wrote_extrinsics ? "extrinsics.yaml (and as camera_joint.urdf, "
                           "static_transform_publisher.sh, extrinsics_kalibr.yaml), "
                         : "") +
       "report.html, summary.json, states.csv, convergence.png, tracks.csv, tracks.png" +
       (reprojection_message.empty() ? "" : ", reprojection.png") + "\n";
  return s;
}

}  // namespace omnivert::pipeline
