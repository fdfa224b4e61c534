// omnivert calibrate DATASET|RECORDING --out DIR [--refine] [--force]: the main job (a recording
// is imported first: omnivert/pipeline/recording_job.hpp). Tracks the
// vertical lines of the dataset (Sec. 4, 9.1), runs the self-calibration EKF (Sec. 8.2),
// analyses observability (Sec. 8.1), optionally refines the whole run as a batch
// maximum-likelihood problem, and writes extrinsics.yaml, tracks.csv, tracks.png, states.csv,
// convergence.png (Fig. 25), report.html and summary.json.

#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "check_options.hpp"
#include "commands.hpp"
#include "config_file.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "core/yaml_fields.hpp"
#include "import_options.hpp"
#include "omnivert/calib/calibrate.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/pipeline/calibrate_dataset.hpp"
#include "pipeline_options.hpp"
#include "tracker_options.hpp"

namespace omnivert::cli {

namespace {

struct CalibrateArgs {
  std::string dataset;
  std::string out;
  // The job's options tree (recommended presets): flags without a unit to convert are bound
  // to its fields; the prior file, the flags that override it, the tracker's flags and the
  // time offset are applied in run_calibrate.
  pipeline::CalibrateDatasetOptions options;
  std::string prior_file;
  std::vector<std::string> unused_with_tracks;  // extraction/tracking flags given with --tracks
  std::optional<double> phi, rho, psi, sigma_phi, sigma_rho, sigma_psi;
  std::optional<double> bearing_sigma_deg;
  std::optional<double> odometry_inflation;
  std::optional<double> track_bias_sigma_deg;
  double crossing_guard_deg = rad2deg(calib::AssociationOptions{}.crossing_guard);
  TrackerFlags tracker;
  std::string time_offset = "estimate";  // --time-offset: "estimate" or seconds
  CheckFlags check;                      // --check-reference, --check-frames, ...
  ImportFlags import;                    // a recording instead of a dataset folder
  std::string config;
};

// The prior from a YAML file: keys phi, rho, psi, sigma_phi, sigma_rho, sigma_psi [rad, m]
// (the keys of extrinsics.yaml, so a previous result can be the next prior), and optionally
// bearing_sigma [rad], track_bias_sigma [rad], odometry_inflation. Other keys are ignored.
void read_prior_file(const std::string& path, calib::CalibrationOptions* o) {
  const YAML::Node y = yaml::load_file(path);
  if (auto v = yaml::optional_number(y, "phi", path)) o->prior.mean.phi = *v;
  if (auto v = yaml::optional_number(y, "rho", path, true)) o->prior.mean.rho = *v;
  if (auto v = yaml::optional_number(y, "psi", path)) o->prior.mean.psi = *v;
  if (auto v = yaml::optional_number(y, "sigma_phi", path, true)) o->prior.sigma(0) = *v;
  if (auto v = yaml::optional_number(y, "sigma_rho", path, true)) o->prior.sigma(1) = *v;
  if (auto v = yaml::optional_number(y, "sigma_psi", path, true)) o->prior.sigma(2) = *v;
  if (auto v = yaml::optional_number(y, "bearing_sigma", path, true)) o->noise.bearing_sigma = *v;
  if (auto v = yaml::optional_number(y, "track_bias_sigma", path)) o->noise.track_bias_sigma = *v;
  if (auto v = yaml::optional_number(y, "odometry_inflation", path, true))
    o->filter.odometry_inflation = *v;
}

// The calibration's options: the recommended preset with the bound flags, then the dataset's
// prior.yaml (the mount of a recording's /tf_static, written by the import), then the prior
// file, then the flags that override them (the wheel base and K come from wheel0/sensor.yaml in
// the pipeline).
calib::CalibrationOptions calibration_options(const CalibrateArgs& a,
                                              const std::string& dataset_prior) {
  calib::CalibrationOptions opt = a.options.calibration;
  if (!dataset_prior.empty()) read_prior_file(dataset_prior, &opt);
  if (!a.prior_file.empty()) read_prior_file(a.prior_file, &opt);
  if (a.phi) opt.prior.mean.phi = *a.phi;
  if (a.rho) opt.prior.mean.rho = *a.rho;
  if (a.psi) opt.prior.mean.psi = *a.psi;
  if (a.sigma_phi) opt.prior.sigma(0) = *a.sigma_phi;
  if (a.sigma_rho) opt.prior.sigma(1) = *a.sigma_rho;
  if (a.sigma_psi) opt.prior.sigma(2) = *a.sigma_psi;
  if (a.bearing_sigma_deg) opt.noise.bearing_sigma = deg2rad(*a.bearing_sigma_deg);
  if (a.track_bias_sigma_deg) opt.noise.track_bias_sigma = deg2rad(*a.track_bias_sigma_deg);
  if (a.odometry_inflation) opt.filter.odometry_inflation = *a.odometry_inflation;
  opt.association.crossing_guard = deg2rad(a.crossing_guard_deg);
  return opt;
}

// The prior of the dataset's prior.yaml (a recording's /tf_static), its frames and camera
// height where the flags do not give them, and the words naming the prior in the report.
std::string dataset_prior(CLI::App* cmd,
                          const CalibrateArgs& a,
                          const std::string& dataset,
                          pipeline::CalibrateDatasetOptions& o) {
  namespace fs = std::filesystem;
  const std::string file = (fs::path(dataset) / recording::kPriorFile).string();
  std::error_code ec;
  const bool flags = a.phi || a.rho || a.psi;
  if (fs::exists(file, ec)) {
    const YAML::Node y = yaml::load_file(file);
    const std::string source = yaml::optional_string(y, "source", file).value_or(file);
    if (!cmd->get_option("--base-frame")->count())
      o.frames.base = yaml::optional_string(y, "base_frame", file).value_or(o.frames.base);
    if (!cmd->get_option("--camera-frame")->count())
      o.frames.camera = yaml::optional_string(y, "camera_frame", file).value_or(o.frames.camera);
    if (!a.options.frames.camera_height)
      o.frames.camera_height = yaml::optional_number(y, "camera_height", file);
    o.prior_source = source + (!a.prior_file.empty() ? ", then " + a.prior_file : "") +
                     (flags ? ", then the flags" : "");
    std::printf("prior: the camera's mount of %s%s\n",
                source.c_str(),
                flags || !a.prior_file.empty() ? " (overridden by --prior or the flags)" : "");
    return file;
  }
  if (!a.prior_file.empty())
    o.prior_source = a.prior_file + (flags ? ", then the flags" : "");
  else if (flags)
    o.prior_source = "the flags";
  return {};
}

void run_calibrate(CLI::App* cmd, const CalibrateArgs& a) {
  if (a.out.empty()) throw InputError("--out is required");
  ImportFlags import = a.import;  // the prior's frames are calibrate's --base-frame, --camera-frame
  import.o.base_frame = a.options.frames.base;
  if (cmd->get_option("--camera-frame")->count()) import.o.camera_frame = a.options.frames.camera;
  const auto imported = import_for_job(cmd, a.dataset, a.out, import);
  const std::string dataset = imported ? imported->path() : a.dataset;
  pipeline::CalibrateDatasetOptions o = a.options;
  const std::string prior = dataset_prior(cmd, a, dataset, o);
  if (imported) o.input_name = a.dataset + " (imported into " + dataset + ")";
  o.tracker = a.tracker.options();
  o.calibration = calibration_options(a, prior);
  o.reprojection = check_options(a.check);
  o.check_reference = a.check.reference != "auto" && a.check.reference != "none";
  o.check_off = a.check.reference == "none";
  if (a.time_offset != "estimate") o.time_offset_s = std::stod(a.time_offset);
  if (!a.options.frames.camera_height && !a.prior_file.empty()) {
    if (auto h =
            yaml::optional_number(yaml::load_file(a.prior_file), "camera_height", a.prior_file))
      o.frames.camera_height = h;
  }
  o.command = command_line();
  if (!o.tracks_file.empty() && !a.unused_with_tracks.empty()) {
    std::string list;
    for (const std::string& n : a.unused_with_tracks) list += (list.empty() ? "" : ", ") + n;
    o.notes.push_back("--tracks: the tracks are read from " + o.tracks_file + "; " + list +
                      " (extraction and tracking options) did nothing");
  }
  std::optional<Progress> bar;
  const auto start = std::chrono::steady_clock::now();
  double tracking_s = 0;  // from the call to the end of tracking
  std::string bar_stage;
  o.progress = [&](const std::string& stage, std::size_t done, std::size_t total) {
    if (stage == "calibrate") {
      tracking_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (bar) bar->finish(), bar.reset();
      return;
    }
    // "track", "track again", "filter", "refinement: ..." (a bar each); a stage without a
    // known end (the association's rounds, a solve) as a line of its own.
    if (bar && bar_stage != stage) bar->finish(), bar.reset();
    if (total == 0) {
      if (Progress::enabled() && (bar_stage != stage || done > 0))
        std::fprintf(stderr, done > 0 ? "%s: round %zu\n" : "%s\n", stage.c_str(), done);
      bar_stage = stage;
      return;
    }
    if (!bar) bar.emplace(stage, total), bar_stage = stage;
    bar->update(done);
  };
  const pipeline::CalibrateDatasetResult r = pipeline::calibrate_dataset(dataset, a.out, o);
  if (const std::string t = pipeline::tilt_line(r.tilt, r.tilt_corrected); !t.empty())
    std::printf("%s\n", t.c_str());
  std::printf("%s", r.BriefReport().c_str());
  if (!r.streaming_message.empty()) std::printf("%s\n", r.streaming_message.c_str());
  if (o.tracks_file.empty() && tracking_s > 0 && !o.streaming)
    std::printf("tracking: %s\n",
                throughput(r.frames, tracking_s, resolve_threads(a.options.threads)).c_str());
  if (!r.wrote_extrinsics) {
    std::fprintf(stderr,
                 "omnivert: the extrinsics are not determined by this run (%s); extrinsics.yaml "
                 "not written. --force writes it anyway.\n",
                 r.calibration.observability.message.c_str());
    throw CommandExit{kExitUndetermined};
  }
}

// The prior: a file and the flags that override it.
void add_prior_options(CLI::App* cmd, CalibrateArgs& a) {
  const std::string g = "Prior (the initial guess; default: the paper's hand measurement)";
  cmd->add_option("--prior",
                  a.prior_file,
                  "YAML file with phi, rho, psi, sigma_phi, sigma_rho, sigma_psi [rad, m] (an "
                  "extrinsics.yaml works), optional bearing_sigma [rad], odometry_inflation; "
                  "flags override it")
      ->check(CLI::ExistingFile)
      ->group(g);
  cmd->add_option("--phi", a.phi, "Prior phi [rad] (default 0)")->group(g);
  cmd->add_option("--rho", a.rho, "Prior rho [m] (default 0.2)")->check(kNonNegative)->group(g);
  cmd->add_option("--psi", a.psi, "Prior psi [rad] (default 0)")->group(g);
  cmd->add_option("--sigma-phi", a.sigma_phi, "Prior sigma of phi [rad] (default 0.8)")
      ->check(kPositive)
      ->group(g);
  cmd->add_option("--sigma-rho", a.sigma_rho, "Prior sigma of rho [m] (default 0.1)")
      ->check(kPositive)
      ->group(g);
  cmd->add_option("--sigma-psi", a.sigma_psi, "Prior sigma of psi [rad] (default 0.8)")
      ->check(kPositive)
      ->group(g);
}

// The noise models and the calibration input's limits.
void add_model_options(CLI::App* cmd, CalibrateArgs& a) {
  const std::string gm = "Models";
  cmd->add_option("--bearing-sigma",
                  a.bearing_sigma_deg,
                  "Bearing noise sigma [degrees] of the observation model, eq. (30). The default "
                  "(0.025) is what makes the estimate consistent (NEES) on rendered images with "
                  "our extractor (docs/validation.md); the paper used 0.3")
      ->check(kPositive)
      ->group(gm);
  cmd->add_option("--odometry-inflation",
                  a.odometry_inflation,
                  "Factor on the Chong-Kleeman K of wheel0/sensor.yaml, eq. (31), in the filter "
                  "(default 1: K as given; the paper used 5, which costs efficiency when K is "
                  "right and helps when the wheels are off: docs/theory/filter.md#odometry-noise)")
      ->check(kPositive)
      ->group(gm);
  cmd->add_option("--update-iterations",
                  a.options.calibration.filter.update_iterations,
                  "Gauss-Newton iterations of the filter's update per frame (1: the plain EKF; "
                  "more: the iterated EKF, docs/theory/filter.md#updates)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str()
      ->group(gm);
  cmd->add_option("--track-bias-sigma",
                  a.track_bias_sigma_deg,
                  "A constant bearing error per track [degrees], in the filter, the refinement "
                  "and the bounds (default 0: none; --bearing-sigma is then the error that "
                  "changes from frame to frame; measured from pixels it does not make our "
                  "extractor's sigmas consistent in every row: "
                  "docs/theory/filter.md#per-track-bias)")
      ->check(kNonNegative)
      ->group(gm);
  cmd->add_option("--lateral-sigma",
                  a.options.calibration.robot.lateral_sigma,
                  "Sideways slip per image step [m] allowed by the batch problems (the filter's "
                  "window and the refinement); eq. (14) has none. Raise it for a robot that "
                  "slips sideways (docs/theory/refinement.md#odometry-factor)")
      ->check(kPositive)
      ->capture_default_str()
      ->group(gm);
  cmd->add_option("--crowded-sigma",
                  a.options.input.crowded_sigma_scale,
                  "The bearing sigma of a crowded line (tracks.csv's crowded column: another edge "
                  "within a few pixels all along it) is --bearing-sigma times this")
      ->check(kPositive)
      ->capture_default_str()
      ->group(gm);
  cmd->add_option("--calibration-length-fraction",
                  a.options.input.min_annulus_fraction,
                  "Lines shorter than this fraction of the annulus are tracked but their "
                  "bearings are not used by the calibration (0.5: the paper's rule; 0: every "
                  "line). Not given: 0.5, or shorter lines when fewer than 15 tracks hold such "
                  "lines (docs/calibration.md#which-lines)")
      ->check(CLI::Range(0.0, 1.0))
      ->each([&a](const std::string&) { a.options.input.enough_tracks = 0; })
      ->capture_default_str()
      ->group(gm);
  cmd->add_option("--split-after-short",
                  a.options.input.split_after_short,
                  "Where a track's line was shorter than --calibration-length-fraction for at "
                  "least this many frames and is long again, the rest of the track is a new "
                  "track for the calibration (0: never split)")
      ->check(kNonNegative)
      ->capture_default_str()
      ->group(gm);
  cmd->add_option("--time-offset",
                  a.time_offset,
                  "Camera-odometry time offset [s], positive when the image stamps are late: "
                  "the stamps are shifted by it before tracking. 'estimate' (default): "
                  "estimated from the turn the bearings show against the wheels', reported, "
                  "and applied when significant (docs/calibration.md#time-offset); 0 turns it off")
      ->check(CLI::Validator(
          [](const std::string& v) -> std::string {
            if (v == "estimate") return {};
            try {
              std::size_t used = 0;
              const double d = std::stod(v, &used);
              if (used == v.size() && std::isfinite(d) && std::abs(d) <= 10.0) return {};
            } catch (const std::exception&) {
            }
            return "expected 'estimate' or a number of seconds in [-10, 10], got '" + v + "'";
          },
          "estimate|SECONDS"))
      ->capture_default_str()
      ->group(gm);
  cmd->add_option("--max-wheel-gap",
                  a.options.input.max_wheel_gap_s,
                  "Wheel samples further apart than this [s] are a gap: the bearings of the "
                  "images inside it are not used")
      ->check(kPositive)
      ->capture_default_str()
      ->group(gm);
}

// The robot-format files' frames (calib/robot_formats.hpp).
void add_frame_options(CLI::App* cmd, CalibrateArgs& a) {
  const std::string g =
      "Robot formats (camera_joint.urdf, static_transform_publisher.sh, "
      "extrinsics_kalibr.yaml)";
  cmd->add_option("--base-frame", a.options.frames.base, "The robot's frame (parent)")
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--camera-frame", a.options.frames.camera, "The camera's frame (child)")
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--camera-height",
                  a.options.frames.camera_height,
                  "Height of the camera centre above the base frame's origin [m], written as z "
                  "(not estimated: the bearings are 2-D; default: camera_height of --prior, "
                  "else 0)")
      ->group(g);
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto a = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Self-calibrate the camera-to-odometry extrinsics (phi, rho, psi) from a dataset: track "
      "lines, EKF (Sec. 8.2), observability (Sec. 8.1), optional batch refinement");
  cmd->add_option("DATASET",
                  a->dataset,
                  "Dataset folder (cam0/, wheel0/, optional ground_truth/), or a recording (ROS 1 "
                  ".bag, ROS 2 .db3 or .mcap, with the options of `omnivert import`)")
      ->required();
  cmd->add_option("--out", a->out, "Output folder (required)");
  add_config_option(cmd, a->config);
  cmd->add_flag(
      "--refine",
      a->options.calibration.refinement.enabled,
      "Refine the filter's result by batch maximum likelihood over the whole run (Ceres)");
  cmd->add_flag("--streaming",
                a->options.streaming,
                "Calibrate as the robot would while driving: each image through extraction, "
                "tracker and filter as it comes, on one thread, nothing looked ahead; the "
                "estimate after every frame and the time it took in streaming.csv "
                "(docs/calibration.md#streaming). Not with --refine or --tracks");
  cmd->add_option("--split-chi2",
                  a->options.calibration.association.split_chi2,
                  "Filter's window and refinement: split a track in two where two features "
                  "explain its bearings better than one by this likelihood-ratio statistic (a "
                  "track that slipped onto a neighbouring line); 0 turns splitting off")
      ->check(kNonNegative)
      ->capture_default_str();
  cmd->add_flag("!--no-join",
                a->options.calibration.association.join_pieces,
                "Filter (window and after) and refinement: keep a track that starts where a line "
                "the tracker lost is predicted as a line of its own, instead of joining it to that "
                "line (docs/theory/association.md#pieces-of-one-line)");
  cmd->add_option("--join-prediction-sigmas",
                  a->options.calibration.association.join_prediction_sigmas,
                  "Filter after the window: join a new track to a lost line only where that "
                  "line's predicted bearing has a sigma of at most this many bearing sigmas; 0: "
                  "no limit")
      ->check(kNonNegative)
      ->capture_default_str();
  cmd->add_option("--crossing-guard",
                  a->crossing_guard_deg,
                  "Leave out a track's bearings while another line is predicted within this "
                  "angle [degrees] of it (the extractor merges lines that close, and the "
                  "bearing is pulled; docs/theory/association.md#lines-that-cross); 0 turns it off")
      ->check(CLI::Range(0.0, 20.0))
      ->capture_default_str();
  cmd->add_flag("!--no-noise-check",
                a->options.calibration.noise_check.enabled,
                "Report the model's covariances as they are, without the data's check of the "
                "bearing noise (errors summed along each track; docs/theory/noise-check.md)");
  cmd->add_option("--noise-check-lower-level",
                  a->options.calibration.noise_check.lower_level,
                  "The noise check finds the bearings less noisy than the model assumes when "
                  "errors this small have at most this probability under the model, and then "
                  "shrinks the bearings' share of the covariance where the tracker kept its "
                  "lines (docs/theory/noise-check.md); 0 turns this side off")
      ->check(kTestLevel)
      ->capture_default_str();
  cmd->add_option("--tracks",
                  a->options.tracks_file,
                  "Calibrate from this tracks.csv (of `omnivert track` or an earlier calibrate "
                  "on the same dataset) instead of extracting and tracking the images")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--force",
                a->options.force,
                "Write extrinsics.yaml (and exit 0) even when the run does not determine every "
                "parameter");
  add_prior_options(cmd, *a);
  add_model_options(cmd, *a);
  add_frame_options(cmd, *a);
  add_check_options(cmd, a->check, "--check-");
  add_pipeline_options(cmd, a->options.features);
  add_mask_option(cmd, a->options.mask);
  add_tilt_options(cmd, a->options.tilt);
  add_tracker_options(cmd, a->tracker);
  add_threads_option(cmd, a->options.threads);
  add_import_options(cmd, a->import, true);
  cmd->callback([a, cmd] {
    apply_config(cmd, a->config);
    // Extraction and tracking flags given with --tracks do nothing: say so.
    a->unused_with_tracks.clear();
    for (const CLI::Option* o : cmd->get_options())
      if (o->count() > 0 &&
          (o->get_group() == kExtractionGroup || o->get_group() == kDescriptorGroup ||
           o->get_group() == kTrackingGroup))
        a->unused_with_tracks.push_back(o->get_name());
    run_calibrate(cmd, *a);
  });
}

}  // namespace omnivert::cli
