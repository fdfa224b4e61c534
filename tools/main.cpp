// omnivert: vertical lines in omnidirectional images, from pixels to camera-odometry
// calibration. See README.md and `omnivert <command> --help`.

#include <cstdio>
#include <exception>
#include <string>

#include <glog/logging.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::cli {
namespace {
std::string g_command_line;
}
void set_command_line(int argc, char** argv) {
  g_command_line.clear();
  for (int i = 0; i < argc; ++i) {
    if (i) g_command_line += ' ';
    const std::string a = argv[i];
    const bool quote = a.empty() || a.find_first_of(" \t'\"$") != std::string::npos;
    g_command_line += quote ? "'" + a + "'" : a;
  }
}
const std::string& command_line() { return g_command_line; }
}  // namespace omnivert::cli

int main(int argc, char** argv) {
  // Warnings and log lines go to stderr: stdout carries results (tables, summaries).
  spdlog::set_default_logger(spdlog::stderr_color_mt("omnivert"));
  // Ceres logs through glog: to stderr, never to files, and only its errors (its warnings,
  // such as a rank-deficient Jacobian that the covariance then falls back from, are ours to
  // report); with -v its warnings too.
  FLAGS_logtostderr = true;
  FLAGS_minloglevel = google::GLOG_ERROR;
  google::InitGoogleLogging(argv[0]);
  CLI::App app{
      "omnivert: vertical lines in omnidirectional images (extraction, description, "
      "tracking, camera-odometry self-calibration)"};
  app.require_subcommand(1);
  // Set while parsing, before the subcommand's callback runs.
  app.add_flag_callback(
         "-v,--verbose",
         [] {
           spdlog::set_level(spdlog::level::debug);
           FLAGS_minloglevel = google::GLOG_WARNING;
         },
         "More log output (each calibration stage's time, for one)")
      ->trigger_on_parse();
  app.set_version_flag("--version", "omnivert 0.1.0");

  omnivert::cli::add_extract_command(app);
  omnivert::cli::add_camera_command(app);
  omnivert::cli::add_pattern_command(app);
  omnivert::cli::add_simulate_command(app);
  omnivert::cli::add_track_command(app);
  omnivert::cli::add_evaluate_command(app);
  omnivert::cli::add_study_command(app);
  omnivert::cli::add_calibrate_command(app);
  omnivert::cli::add_import_command(app);
  omnivert::cli::add_reproject_command(app);
  omnivert::cli::set_command_line(argc, argv);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : omnivert::cli::kExitBadInput;
  } catch (const omnivert::InputError& e) {
    std::fprintf(stderr, "omnivert: error: %s\n", e.what());
    return omnivert::cli::kExitBadInput;
  } catch (const omnivert::cli::CommandExit& e) {
    return e.code;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "omnivert: error: %s\n", e.what());
    return omnivert::cli::kExitFailure;
  }
  return 0;
}
