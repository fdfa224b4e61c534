// omnivert track DATASET|RECORDING --out DIR: lines tracked through a video (Sec. 4, 9.1); a
// recording is imported first (omnivert/pipeline/recording_job.hpp).

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <spdlog/spdlog.h>

#include "commands.hpp"
#include "config_file.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "import_options.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/pipeline/track_dataset.hpp"
#include "omnivert/viz/tracks_plot.hpp"
#include "pipeline_options.hpp"
#include "tracker_options.hpp"

namespace omnivert::cli {

namespace {

struct TrackArgs {
  std::string dataset;
  std::string out;
  FeaturePipelineOptions pipeline;
  std::string mask;
  pipeline::TiltCheckOptions tilt;
  TrackerFlags tracker;
  int threads = 0;
  ImportFlags import;
  std::string config;
};

void run_track(CLI::App* cmd, const TrackArgs& a) {
  namespace fs = std::filesystem;
  std::string why;
  if (a.out.empty()) throw InputError("--out is required");
  if (!a.pipeline.IsValid(&why)) throw InputError("invalid extraction options: " + why);
  const auto imported = import_for_job(cmd, a.dataset, a.out, a.import);
  dataset::LoadOptions lo;
  lo.require_wheel = false;
  lo.allow_missing_images = true;  // a missing frame is warned about and skipped (no lines)
  const auto data = dataset::Dataset::load(imported ? imported->path() : a.dataset, lo);
  for (const std::string& n : data.notes()) spdlog::debug("{}", n);
  std::error_code ec;
  fs::create_directories(a.out, ec);
  if (ec) throw InputError(a.out, 0, "cannot create the output folder: " + ec.message());

  pipeline::TrackDatasetOptions o;
  o.pipeline = a.pipeline;
  o.mask = a.mask;
  o.tilt = a.tilt;
  o.tracker = a.tracker.options();
  o.threads = a.threads;
  Progress bar("track", data.size());
  const auto start = std::chrono::steady_clock::now();
  const auto r =
      pipeline::track_dataset(data, o, [&](std::size_t done, std::size_t) { bar.update(done); });
  const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
  bar.finish();
  for (const auto& w : r.warnings) spdlog::warn("{}", w);

  const fs::path csv = fs::path(a.out) / "tracks.csv";
  const fs::path png = fs::path(a.out) / "tracks.png";
  write_tracks_csv(csv, r.rows);
  viz::write_tracks_png(png, r.rows);
  std::printf("%lld frames (%lld skipped), %zu detections, %lld tracks\n%s\n",
              static_cast<long long>(r.frames),
              static_cast<long long>(r.frames_skipped),
              r.rows.size(),
              static_cast<long long>(r.stats.new_tracks),
              r.stats.BriefReport().c_str());
  if (const std::string t = pipeline::tilt_line(r.tilt, r.tilt_corrected); !t.empty())
    std::printf("%s\n", t.c_str());
  std::printf("%s\n", throughput(r.frames, took.count(), resolve_threads(a.threads)).c_str());
  std::printf("wrote %s and %s\n", csv.c_str(), png.c_str());
}

}  // namespace

void add_track_command(CLI::App& app) {
  auto a = std::make_shared<TrackArgs>();
  CLI::App* cmd = app.add_subcommand(
      "track", "Track vertical lines through a dataset (tracks.csv, tracks.png)");
  cmd->add_option("DATASET",
                  a->dataset,
                  "Dataset folder (cam0/, optional wheel0/), or a recording (ROS 1 .bag, ROS 2 "
                  ".db3 or .mcap, with the options of `omnivert import`)")
      ->required();
  cmd->add_option("--out", a->out, "Output folder (required)");
  add_config_option(cmd, a->config);
  add_pipeline_options(cmd, a->pipeline);
  add_mask_option(cmd, a->mask);
  add_tilt_options(cmd, a->tilt);
  add_tracker_options(cmd, a->tracker);
  add_threads_option(cmd, a->threads);
  add_import_options(cmd, a->import, true);
  cmd->callback([a, cmd] {
    apply_config(cmd, a->config);
    run_track(cmd, *a);
  });
}

}  // namespace omnivert::cli
