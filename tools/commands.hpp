#pragma once
// Subcommands of the omnivert tool. Each add_*_command declares its options on the app and
// sets a callback that does the work through the library.
//
// Exit codes, for every subcommand:
//   0 success; 1 the work failed (a message says why); 2 bad input or usage (file, line,
//   problem); 3 the result is not determined (calibrate: unobservable trajectory).

#include <string>

#include <CLI/CLI.hpp>

namespace omnivert::cli {

inline constexpr int kExitFailure = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitUndetermined = 3;

// Number checks with plain messages ("--x: must be a number >= 0, got -1"); CLI11's own
// NonNegativeNumber prints the largest double as the upper end of its range. `what` names
// the accepted values ("a number >= 0"), `ok` tests one.
template <typename Ok>
CLI::Validator number_check(const std::string& what, Ok ok, const std::string& shown) {
  return CLI::Validator(
      [what, ok](std::string& in) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(in, v) || !ok(v)) return "must be " + what + ", got " + in;
        return std::string();
      },
      shown);
}
inline CLI::Validator number_at_least(double low, bool strict) {
  const std::string what = std::string(strict ? "> " : ">= ") + CLI::detail::to_string(low);
  return number_check(
      "a number " + what,
      [low, strict](double v) { return strict ? v > low : v >= low; },
      "NUMBER " + what);
}
inline const CLI::Validator kNonNegative = number_at_least(0.0, false);
// A test's level: 0 (the test off) up to, not including, 0.5.
inline const CLI::Validator kTestLevel = number_check(
    "a number >= 0 and < 0.5", [](double v) { return v >= 0.0 && v < 0.5; }, "LEVEL in [0, 0.5)");
inline const CLI::Validator kPositive = number_at_least(0.0, true);

// Thrown by a command's callback to end with a given code after printing `what()`.
struct CommandExit {
  int code;
};

void add_extract_command(CLI::App& app);
// omnivert camera: centre, annulus and mask of a new camera (tools/cmd_camera.cpp).
void add_camera_command(CLI::App& app);
void add_pattern_command(CLI::App& app);
// omnivert simulate: render a dataset with ground truth (tools/cmd_simulate.cpp).
void add_simulate_command(CLI::App& app);
void add_track_command(CLI::App& app);
void add_evaluate_command(CLI::App& app);
// omnivert study similarity|sensitivity|baselines: the descriptor study (tools/cmd_study.cpp).
void add_study_command(CLI::App& app);
// `study real-images`, a subcommand of `study` (tools/cmd_study_real.cpp).
void add_real_images_study(CLI::App* study);
// omnivert calibrate: the main job (tools/cmd_calibrate.cpp).
void add_calibrate_command(CLI::App& app);
// omnivert import: a ROS 1 or ROS 2 recording into a dataset folder (tools/cmd_import.cpp).
void add_import_command(CLI::App& app);
// omnivert reproject: the check by eye of a mounting (tools/cmd_reproject.cpp).
void add_reproject_command(CLI::App& app);

// The command line as given (for reports), set by main().
void set_command_line(int argc, char** argv);
const std::string& command_line();

}  // namespace omnivert::cli
