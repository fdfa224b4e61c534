// omnivert import RECORDING --out DATASET: a ROS 1 or ROS 2 recording turned into a dataset
// folder (docs/import.md). The library does the work (omnivert/recording/import.hpp).

#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include <spdlog/spdlog.h>

#include "commands.hpp"
#include "config_file.hpp"
#include "core/progress.hpp"
#include "import_options.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/recording/import.hpp"

namespace omnivert::cli {

namespace {

struct ImportArgs {
  std::string recording;
  bool list = false;
  std::string config;
  ImportFlags flags;
};

void run_import(const ImportArgs& a) {
  auto rec = recording::open_recording(a.recording);
  if (a.list) {
    std::printf("%s: %s\n%s",
                rec->path().c_str(),
                rec->format().c_str(),
                recording::topics_table(*rec).c_str());
    return;
  }
  recording::ImportOptions o = import_options(a.flags);
  if (o.out.empty()) throw InputError("--out is required (or --list)");
  if (o.image_topic.empty()) {
    throw InputError("--image-topic is required; the recording has:\n" +
                     recording::topics_table(*rec));
  }
  std::unique_ptr<Progress> bar;
  o.progress = [&bar](std::uint64_t done, std::uint64_t total) {
    if (!bar) bar = std::make_unique<Progress>("import", static_cast<std::size_t>(total));
    bar->update(static_cast<std::size_t>(done));
  };
  const auto s = recording::import_recording(*rec, o);
  if (bar) bar->finish();
  for (const auto& w : s.warnings) spdlog::warn("{}", w);
  std::printf("%s: %zu images (%dx%d %s, %.3f to %.3f s)",
              s.format.c_str(),
              s.images,
              s.width,
              s.height,
              s.image_encoding.c_str(),
              s.image_start_s,
              s.image_end_s);
  if (s.wheel_samples > 0) {
    std::printf(
        ", %zu wheel samples (%.3f to %.3f s)", s.wheel_samples, s.wheel_start_s, s.wheel_end_s);
  }
  if (s.laser_scans > 0) std::printf(", %zu laser scans", s.laser_scans);
  std::printf("\n");
  if (s.wheel_base_from_description || s.wheel_radius_from_description) {
    std::printf("from the recording's /robot_description: wheel base %.4f m, wheel radius %.4f m\n",
                s.wheel_base,
                s.wheel_radius);
  }
  if (s.mount) {
    std::printf("prior from %s: phi %.3f deg, rho %.1f mm, psi %.3f deg, height %.1f mm (%s)\n",
                s.mount_source.c_str(),
                rad2deg(s.mount->phi),
                s.mount->rho * 1e3,
                rad2deg(s.mount->psi),
                s.mount->height * 1e3,
                recording::kPriorFile);
  } else {
    std::printf("no prior from the recording: %s\n", s.mount_source.c_str());
  }
  std::printf("wrote %s\n", o.out.c_str());
}

}  // namespace

void add_import_command(CLI::App& app) {
  auto a = std::make_shared<ImportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "import",
      "Turn a ROS 1 bag or a ROS 2 bag (.db3, .mcap) into a dataset folder (docs/import.md)");
  cmd->add_option(
         "RECORDING", a->recording, "ROS 1 .bag, ROS 2 .db3 or .mcap file, or a ROS 2 bag folder")
      ->required();
  cmd->add_flag(
      "--list", a->list, "Print the recording's topics, types and message counts, and stop");
  add_import_options(cmd, a->flags, false);
  cmd->add_option("--base-frame",
                  a->flags.o.base_frame,
                  "The robot's frame of the camera's mount in /tf_static (the prior)")
      ->capture_default_str();
  cmd->add_option("--camera-frame",
                  a->flags.o.camera_frame,
                  "The camera's frame in /tf_static (default: the images' header.frame_id)");
  add_config_option(cmd, a->config);
  cmd->callback([a, cmd] {
    apply_config(cmd, a->config);
    run_import(*a);
  });
}

}  // namespace omnivert::cli
