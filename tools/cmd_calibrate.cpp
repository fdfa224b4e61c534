// omnivert calibrate DATASET --out DIR [--refine] [--force]: the main job. Tracks the
// vertical lines of the dataset (Sec. 4, 9.1), runs the self-calibration EKF (Sec. 8.2),
// analyses observability (Sec. 8.1), optionally refines the whole run as a batch
// maximum-likelihood problem, and writes extrinsics.yaml, tracks.csv, tracks.png, states.csv,
// convergence.png (Fig. 25), report.html and summary.json.

#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "commands.hpp"
#include "omnivert/calib/calibrate.hpp"
#include "omnivert/calib/dataset_run.hpp"
#include "omnivert/calib/report.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/core/image_io.hpp"
#include "omnivert/core/progress.hpp"
#include "omnivert/core/yaml_fields.hpp"
#include "omnivert/match/track_dataset.hpp"
#include "omnivert/match/tracks_plot.hpp"
#include "pipeline_options.hpp"
#include "tracker_options.hpp"

namespace omnivert::cli {

namespace {

// The bearing noise of our extractor on rendered images, as the calibration needs it for a
// consistent estimate (docs/calib.md, "From pixels"): 0.025 degree once the bearings of lines
// that cross are left out (before the crossing guard the pulled bearings needed 0.05); it is
// the noisiest of our worlds' bearings (office), and the noise check enlarges the covariance
// where a run's bearings are noisier. The paper's 0.3 degree is 12x looser.
constexpr double kDefaultBearingSigmaDeg = 0.025;
// A constant bearing error per track (calib::Options::track_bias_sigma), degrees; 0: none.
constexpr double kDefaultTrackBiasSigmaDeg = 0.0;

struct CalibrateArgs {
  std::string dataset;
  std::string out;
  bool refine = false;
  bool noise_check = true;
  double noise_check_lower_level = calib::CalibrateOptions{}.noise_check_lower_level;
  bool force = false;
  std::string prior_file;
  std::string tracks_file;  // --tracks: an existing tracks.csv instead of tracking
  std::vector<std::string> unused_with_tracks;  // extraction/tracking flags given with --tracks
  std::optional<double> phi, rho, psi, sigma_phi, sigma_rho, sigma_psi;
  std::optional<double> bearing_sigma_deg;
  std::optional<double> odometry_inflation;
  double max_wheel_gap = 0.5;
  double crowded_sigma = calib::DatasetRunOptions{}.crowded_sigma_scale;
  double split_chi2 = calib::BatchOptions{}.split_chi2;
  bool no_join = false;
  double lateral_sigma = calib::BatchOptions{}.lateral_sigma;
  std::optional<double> track_bias_sigma_deg;
  double crossing_guard_deg = rad2deg(calib::Options{}.crossing_guard);
  FeaturePipelineOptions pipeline;
  TrackerFlags tracker;
};

// The prior from a YAML file: keys phi, rho, psi, sigma_phi, sigma_rho, sigma_psi [rad, m]
// (the keys of extrinsics.yaml, so a previous result can be the next prior), and optionally
// bearing_sigma [rad], track_bias_sigma [rad], odometry_inflation. Other keys are ignored.
void read_prior_file(const std::string& path, calib::Options* o) {
  const YAML::Node y = yaml::load_file(path);
  if (auto v = yaml::optional_number(y, "phi", path)) o->prior.phi = *v;
  if (auto v = yaml::optional_number(y, "rho", path, true)) o->prior.rho = *v;
  if (auto v = yaml::optional_number(y, "psi", path)) o->prior.psi = *v;
  if (auto v = yaml::optional_number(y, "sigma_phi", path, true)) o->prior_sigma(0) = *v;
  if (auto v = yaml::optional_number(y, "sigma_rho", path, true)) o->prior_sigma(1) = *v;
  if (auto v = yaml::optional_number(y, "sigma_psi", path, true)) o->prior_sigma(2) = *v;
  if (auto v = yaml::optional_number(y, "bearing_sigma", path, true)) o->bearing_sigma = *v;
  if (auto v = yaml::optional_number(y, "track_bias_sigma", path)) o->track_bias_sigma = *v;
  if (auto v = yaml::optional_number(y, "odometry_inflation", path, true)) o->odometry_inflation = *v;
}

void remove_if_exists(const std::filesystem::path& p) {
  std::error_code ec;
  std::filesystem::remove(p, ec);
}

// --tracks: the rows of an earlier tracks.csv (`omnivert track` or `calibrate`), checked
// against the dataset: every row's frame must be one of its images, with that image's
// timestamp (a tracks.csv of another dataset, or of a re-recorded one, is refused by file and
// line).
TrackDatasetResult tracks_of_dataset(const std::string& file, const dataset::Dataset& data) {
  TrackDatasetResult t;
  t.rows = read_tracks_csv(file);
  const auto& images = data.images();
  std::set<std::int64_t> ids;
  for (const TrackRow& r : t.rows) {
    const int line = r.source_line;
    if (r.frame >= static_cast<std::int64_t>(images.size()))
      throw InputError(file, line,
                       "frame " + std::to_string(r.frame) + " is not an image of " + data.root() +
                           " (it has " + std::to_string(images.size()) + ")");
    const auto& im = images[static_cast<std::size_t>(r.frame)];
    if (r.timestamp_ns != im.timestamp_ns)
      throw InputError(file, line,
                       "frame " + std::to_string(r.frame) + " has timestamp " +
                           std::to_string(r.timestamp_ns) + " but cam0/data.csv line " +
                           std::to_string(im.line) + " has " + std::to_string(im.timestamp_ns) +
                           ": these tracks are not of this dataset");
    ids.insert(r.track_id);
  }
  t.frames = static_cast<std::int64_t>(images.size());
  t.stats.new_tracks = static_cast<std::int64_t>(ids.size());
  return t;
}

calib::BatchOptions batch_options(const CalibrateArgs& a) {
  calib::BatchOptions b;
  b.split_chi2 = a.split_chi2;
  b.lateral_sigma = a.lateral_sigma;
  b.merge_pieces = !a.no_join;
  return b;
}

void run_calibrate(const CalibrateArgs& a) {
  namespace fs = std::filesystem;
  using clock = std::chrono::steady_clock;
  std::string why;
  if (!a.pipeline.IsValid(&why)) throw InputError("invalid extraction options: " + why);

  // Options: defaults (the paper's hand measurement, wide sigmas), then the dataset's wheel
  // sensor, then the prior file, then the flags.
  dataset::LoadOptions lo;
  lo.require_wheel = true;
  lo.allow_missing_images = true;
  const auto data = dataset::Dataset::load(a.dataset, lo);
  calib::Options opt = calib::options_from_dataset(data);
  opt.bearing_sigma = deg2rad(kDefaultBearingSigmaDeg);
  opt.track_bias_sigma = deg2rad(kDefaultTrackBiasSigmaDeg);
  if (!a.prior_file.empty()) read_prior_file(a.prior_file, &opt);
  if (a.phi) opt.prior.phi = *a.phi;
  if (a.rho) opt.prior.rho = *a.rho;
  if (a.psi) opt.prior.psi = *a.psi;
  if (a.sigma_phi) opt.prior_sigma(0) = *a.sigma_phi;
  if (a.sigma_rho) opt.prior_sigma(1) = *a.sigma_rho;
  if (a.sigma_psi) opt.prior_sigma(2) = *a.sigma_psi;
  if (a.bearing_sigma_deg) opt.bearing_sigma = deg2rad(*a.bearing_sigma_deg);
  if (a.track_bias_sigma_deg) opt.track_bias_sigma = deg2rad(*a.track_bias_sigma_deg);
  if (a.odometry_inflation) opt.odometry_inflation = *a.odometry_inflation;
  opt.split_chi2 = a.split_chi2;
  opt.join_pieces = !a.no_join;
  opt.lateral_sigma = a.lateral_sigma;
  opt.crossing_guard = deg2rad(a.crossing_guard_deg);
  if (!opt.IsValid(&why)) throw InputError("invalid calibration options: " + why);

  // Read before the output folder is cleared: --tracks may name DIR/tracks.csv itself.
  std::optional<TrackDatasetResult> given_tracks;
  if (!a.tracks_file.empty()) given_tracks = tracks_of_dataset(a.tracks_file, data);

  std::error_code ec;
  fs::create_directories(a.out, ec);
  if (ec) throw InputError(a.out, 0, "cannot create the output folder: " + ec.message());
  const fs::path out(a.out);
  // A result of an earlier run must not pass for this run's.
  for (const char* f : {"extrinsics.yaml", "summary.json", "report.html", "states.csv",
                        "convergence.png", "tracks.csv", "tracks.png"})
    remove_if_exists(out / f);

  // 1. Tracking (Sec. 4, 9.1), or the tracks of an earlier run (--tracks).
  const auto t0 = clock::now();
  TrackDatasetResult tracked;
  if (!given_tracks) {
    TrackDatasetOptions to;
    to.pipeline = a.pipeline;
    to.tracker = a.tracker.options();
    Progress bar("track", data.size());
    tracked = track_dataset(data, to, [&](std::size_t done, std::size_t) { bar.update(done); });
    bar.finish();
  } else {
    tracked = std::move(*given_tracks);
  }
  std::vector<std::string> warnings = tracked.warnings;
  write_tracks_csv(out / "tracks.csv", tracked.rows);
  write_tracks_png(out / "tracks.png", tracked.rows);
  const auto t1 = clock::now();

  // 2. The calibration's input, then the filter, observability and refinement (Sec. 8).
  calib::DatasetRunOptions ro;
  ro.max_wheel_gap_s = a.max_wheel_gap;
  ro.crowded_sigma_scale = a.crowded_sigma;
  const calib::DatasetRun run = calib::calibration_run_from_tracks(data, tracked.rows, ro);
  warnings.insert(warnings.end(), run.warnings.begin(), run.warnings.end());
  {
    // Few lines: measured on the simulator's office (docs/calib.md, "Shorter lines"), about
    // 10 tracks at the paper's 50% length gave a median camera yaw error of 0.14-0.17 degree
    // over 50 runs; 25% lines with --refine gave 0.006 degree.
    constexpr int kFewTracks = 15;
    if (run.tracks < kFewTracks) {
      std::string w = "only " + std::to_string(run.tracks) +
                      " lines were tracked: the estimate rests on few features and may be off by "
                      "more than its sigma";
      if (a.pipeline.lines.threshold == LineThreshold::kFractionOfAnnulus &&
          a.pipeline.lines.length_fraction > 0.3)
        w += "; shorter lines help (--length-fraction 0.25 with --refine; docs/calib.md, "
             "\"Shorter lines\")";
      warnings.push_back(w);
    }
  }
  if (given_tracks && !a.unused_with_tracks.empty()) {
    std::string list;
    for (const std::string& n : a.unused_with_tracks) list += (list.empty() ? "" : ", ") + n;
    warnings.push_back("--tracks: the tracks are read from " + a.tracks_file + "; " + list +
                       " (extraction and tracking options) did nothing");
  }
  for (const auto& w : warnings) spdlog::warn("{}", w);
  if (Progress::enabled()) std::fprintf(stderr, "calibrate: filter%s...\n", a.refine ? " and refinement" : "");
  const calib::CalibrationResult result =
      calib::calibrate(run.run,
                       opt,
                       {.refine = a.refine,
                        .noise_check = a.noise_check,
                        .noise_check_lower_level = a.noise_check_lower_level,
                        .batch = batch_options(a)});
  const auto t2 = clock::now();
  if (!result.extrinsics.vec().allFinite() || !result.covariance.allFinite())
    throw std::runtime_error(
        "the calibration diverged (non-finite estimate); nothing written but tracks.csv. Check "
        "the wheel base and K in wheel0/sensor.yaml and the tracks in tracks.png");
  for (const std::string& w : calib::result_warnings(result)) {
    spdlog::warn("{}", w);
    warnings.push_back(w);
  }

  const bool observable = result.observable();
  const bool write_extrinsics = observable || a.force;
  const int exit_code = write_extrinsics ? 0 : kExitUndetermined;

  std::optional<calib::Extrinsics> truth;
  if (data.ground_truth() && data.ground_truth()->extrinsics) {
    const auto& g = *data.ground_truth()->extrinsics;
    truth = calib::Extrinsics{g.phi, g.rho, g.psi};
  }

  // 3. Outputs (each written to a temporary name and renamed: none is left partial).
  calib::write_states_csv((out / "states.csv").string(), result.filter.history);
  std::optional<calib::Extrinsics> refined;
  if (result.refined && result.refinement.covariance_ok) refined = result.refinement.extrinsics;
  write_image_atomic((out / "convergence.png").string(),
                     calib::draw_convergence(result.filter.history, truth, refined));
  calib::ReportInputs ri;
  ri.dataset = a.dataset;
  ri.command = command_line();
  ri.frames = tracked.frames;
  ri.frames_skipped = tracked.frames_skipped;
  ri.detections = static_cast<std::int64_t>(tracked.rows.size());
  ri.tracks_total = tracked.stats.new_tracks;
  ri.run = &run;
  ri.options = opt;
  ri.options.bearing_sigma = result.bearing_sigma;
  ri.truth = truth;
  ri.force = a.force;
  ri.exit_code = exit_code;
  ri.seconds_tracking = std::chrono::duration<double>(t1 - t0).count();
  ri.seconds_calibration = std::chrono::duration<double>(t2 - t1).count();
  ri.warnings = warnings;
  ri.wrote_extrinsics = write_extrinsics;
  if (write_extrinsics) calib::write_extrinsics_yaml((out / "extrinsics.yaml").string(), result);
  write_text_atomic((out / "summary.json").string(), calib::summary_json(result, ri));
  write_text_atomic((out / "report.html").string(), calib::report_html(result, ri));

  // 4. On stdout: the estimate, the verdict, the comparison with the truth when known.
  const auto& e = result.extrinsics;
  const auto& C = result.covariance;
  const auto& o = result.observability;
  std::printf("%lld frames (%lld skipped), %zu detections, %d tracks used, %d bearings; "
              "%.2f m driven, %.0f deg turned\n",
              static_cast<long long>(tracked.frames), static_cast<long long>(tracked.frames_skipped),
              tracked.rows.size(), run.tracks, run.observations, run.path_length,
              rad2deg(run.rotation));
  std::printf("%s estimate:  phi %.3f +- %.3f deg   rho %.2f +- %.2f mm   psi %.3f +- %.3f deg\n",
              refined ? "refined" : "filter", rad2deg(e.phi), rad2deg(std::sqrt(C(0, 0))),
              e.rho * 1e3, std::sqrt(C(1, 1)) * 1e3, rad2deg(e.psi), rad2deg(std::sqrt(C(2, 2))));
  const Eigen::Vector2d p = e.position();
  std::printf("camera in the robot frame: x %.2f mm, y %.2f mm, yaw %.3f deg\n", p(0) * 1e3,
              p(1) * 1e3, rad2deg(e.yaw()));
  if (result.noise_checked)
    std::printf("bearing sigma %s; %s\n",
                calib::bearing_noise_text(result.bearing_sigma, result.track_bias_sigma).c_str(),
                calib::noise_check_line(result).c_str());
  else
    std::printf("bearing sigma %s (no noise check%s)\n",
                calib::bearing_noise_text(result.bearing_sigma, result.track_bias_sigma).c_str(),
                a.noise_check ? ": the run does not determine the extrinsics" : "");
  if (const std::string w = calib::wheel_check_line(result); !w.empty()) std::printf("%s\n", w.c_str());
  if (result.refined && result.refinement.num_splits > 0)
    std::printf("refinement: %d tracks split where they changed line (summary.json lists them)\n",
                result.refinement.num_splits);
  if (!result.filter.joins.empty())
    std::printf("filter: %zu tracks joined to the line they continue after the tracker lost it\n",
                result.filter.joins.size());
  if (result.refined && !result.refinement.merges.empty())
    std::printf("refinement: %zu tracks joined to the line they continue after the tracker lost "
                "it (summary.json lists them)\n",
                result.refinement.merges.size());
  std::printf("Cramer-Rao bound of this run: phi %.3f deg, rho %.2f mm, psi %.3f deg\n",
              rad2deg(o.phi.crlb), o.rho.crlb * 1e3, rad2deg(o.psi.crlb));
  if (truth) {
    auto show = [&](const char* name, const calib::Extrinsics& est, const Eigen::Matrix3d& cov) {
      const auto er = calib::errors_vs_truth(est, cov, *truth);
      std::printf("error vs ground truth (%s): phi %.3f deg, rho %.2f mm, psi %.3f deg, "
                  "position %.2f mm, yaw %.3f deg, NEES %.2f\n",
                  name, rad2deg(er.phi), er.rho * 1e3, rad2deg(er.psi), er.position * 1e3,
                  rad2deg(er.yaw), er.nees);
    };
    show("filter", result.filter.extrinsics, result.filter.covariance);
    if (refined) show("refinement", result.refinement.extrinsics, result.refinement.covariance);
  }
  std::printf("%s\n", o.message.c_str());
  std::printf("results in %s: %sreport.html, summary.json, states.csv, convergence.png, "
              "tracks.csv, tracks.png\n",
              out.c_str(), write_extrinsics ? "extrinsics.yaml, " : "");
  if (!write_extrinsics) {
    std::fprintf(stderr,
                 "omnivert: the extrinsics are not determined by this run (%s); extrinsics.yaml "
                 "not written. --force writes it anyway.\n",
                 o.message.c_str());
    throw CommandExit{kExitUndetermined};
  }
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto a = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Self-calibrate the camera-to-odometry extrinsics (phi, rho, psi) from a dataset: track "
      "lines, EKF (Sec. 8.2), observability (Sec. 8.1), optional batch refinement");
  cmd->add_option("DATASET", a->dataset, "Dataset folder (cam0/, wheel0/, optional ground_truth/)")
      ->required();
  cmd->add_option("--out", a->out, "Output folder")->required();
  cmd->add_flag("--refine", a->refine,
                "Refine the filter's result by batch maximum likelihood over the whole run (Ceres)");
  cmd->add_option("--split-chi2", a->split_chi2,
                  "Filter's window and refinement: split a track in two where two features "
                  "explain its bearings better than one by this likelihood-ratio statistic (a "
                  "track that slipped onto a neighbouring line); 0 turns splitting off")
      ->check(kNonNegative)
      ->capture_default_str();
  cmd->add_flag("--no-join", a->no_join,
                "Filter (window and after) and refinement: keep a track that starts where a line "
                "the tracker lost is predicted as a line of its own, instead of joining it to that "
                "line (docs/calib.md, \"Broken tracks\")");
  cmd->add_option("--crossing-guard", a->crossing_guard_deg,
                  "Leave out a track's bearings while another line is predicted within this "
                  "angle [degrees] of it (the extractor merges lines that close, and the "
                  "bearing is pulled; docs/calib.md, \"Lines that cross\"); 0 turns it off")
      ->check(CLI::Range(0.0, 20.0))
      ->capture_default_str();
  cmd->add_flag("!--no-noise-check", a->noise_check,
                "Report the model's covariances as they are, without the data's check of the "
                "bearing noise (errors summed along each track; docs/calib.md, \"The noise check\")");
  cmd->add_option("--noise-check-lower-level",
                  a->noise_check_lower_level,
                  "The noise check finds the bearings less noisy than the model assumes when "
                  "errors this small have at most this probability under the model, and then "
                  "shrinks the bearings' share of the covariance where the tracker kept its "
                  "lines (docs/calib.md, \"The noise check\"); 0 turns this side off")
      ->check(kTestLevel)
      ->capture_default_str();
  cmd->add_option("--tracks", a->tracks_file,
                  "Calibrate from this tracks.csv (of `omnivert track` or an earlier calibrate "
                  "on the same dataset) instead of extracting and tracking the images")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--force", a->force,
                "Write extrinsics.yaml (and exit 0) even when the run does not determine every "
                "parameter");
  const std::string g = "Prior (the initial guess; default: the paper's hand measurement)";
  cmd->add_option("--prior", a->prior_file,
                  "YAML file with phi, rho, psi, sigma_phi, sigma_rho, sigma_psi [rad, m] (an "
                  "extrinsics.yaml works), optional bearing_sigma [rad], odometry_inflation; "
                  "flags override it")
      ->check(CLI::ExistingFile)
      ->group(g);
  cmd->add_option("--phi", a->phi, "Prior phi [rad] (default 0)")->group(g);
  cmd->add_option("--rho", a->rho, "Prior rho [m] (default 0.2)")->check(kNonNegative)->group(g);
  cmd->add_option("--psi", a->psi, "Prior psi [rad] (default 0)")->group(g);
  cmd->add_option("--sigma-phi", a->sigma_phi, "Prior sigma of phi [rad] (default 0.8)")
      ->check(kPositive)
      ->group(g);
  cmd->add_option("--sigma-rho", a->sigma_rho, "Prior sigma of rho [m] (default 0.1)")
      ->check(kPositive)
      ->group(g);
  cmd->add_option("--sigma-psi", a->sigma_psi, "Prior sigma of psi [rad] (default 0.8)")
      ->check(kPositive)
      ->group(g);
  const std::string gm = "Models";
  cmd->add_option("--bearing-sigma", a->bearing_sigma_deg,
                  "Bearing noise sigma [degrees] of the observation model, eq. (30). The default "
                  "(0.025) is what makes the estimate consistent (NEES) on rendered images with "
                  "our extractor (docs/calib.md); the paper used 0.3")
      ->check(kPositive)
      ->group(gm);
  cmd->add_option("--odometry-inflation", a->odometry_inflation,
                  "Factor on the Chong-Kleeman K of wheel0/sensor.yaml, eq. (31), in the filter "
                  "(default 1: K as given; the paper used 5, which costs efficiency when K is "
                  "right and helps when the wheels are off: docs/calib.md)")
      ->check(kPositive)
      ->group(gm);
  cmd->add_option("--track-bias-sigma", a->track_bias_sigma_deg,
                  "A constant bearing error per track [degrees], in the filter, the refinement "
                  "and the bounds (default 0: none; --bearing-sigma is then the error that "
                  "changes from frame to frame; measured from pixels it does not make our "
                  "extractor's sigmas consistent in every row: docs/calib.md, \"Per-track "
                  "bearing bias\")")
      ->check(kNonNegative)
      ->group(gm);
  cmd->add_option("--lateral-sigma", a->lateral_sigma,
                  "Sideways slip per image step [m] allowed by the batch problems (the filter's "
                  "window and the refinement); eq. (14) has none. Raise it for a robot that "
                  "slips sideways (docs/calib.md, \"lateral sigma\")")
      ->check(kPositive)
      ->capture_default_str()
      ->group(gm);
  cmd->add_option("--crowded-sigma", a->crowded_sigma,
                  "The bearing sigma of a crowded line (tracks.csv's crowded column: another edge "
                  "within a few pixels all along it) is --bearing-sigma times this")
      ->check(kPositive)
      ->capture_default_str()
      ->group(gm);
  cmd->add_option("--max-wheel-gap", a->max_wheel_gap,
                  "Wheel samples further apart than this [s] are a gap: the bearings of the "
                  "images inside it are not used")
      ->check(kPositive)
      ->capture_default_str()
      ->group(gm);
  add_pipeline_options(cmd, a->pipeline);
  add_tracker_options(cmd, a->tracker);
  cmd->callback([a, cmd] {
    // Extraction and tracking flags given with --tracks do nothing: say so.
    a->unused_with_tracks.clear();
    for (const CLI::Option* o : cmd->get_options())
      if (o->count() > 0 && (o->get_group() == kExtractionGroup ||
                             o->get_group() == kDescriptorGroup || o->get_group() == kTrackingGroup))
        a->unused_with_tracks.push_back(o->get_name());
    run_calibrate(*a);
  });
}

}  // namespace omnivert::cli
