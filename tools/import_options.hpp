#pragma once
// The options of `omnivert import` (docs/import.md), shared by `track` and `calibrate`, which
// take a recording in place of a dataset folder with the same options
// (omnivert/pipeline/recording_job.hpp).

#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "omnivert/pipeline/recording_job.hpp"
#include "omnivert/recording/import.hpp"

namespace omnivert::cli {

inline constexpr const char* kRecordingGroup = "Recording (ROS 1 or ROS 2 bag; docs/import.md)";

struct ImportFlags {
  recording::ImportOptions o;
  std::string wheel_joints;        // LEFT,RIGHT
  double odometry_k = -1;          // < 0: not given
  bool keep_dataset = false;       // track, calibrate: keep OUT/dataset
  std::vector<double> laser_pose;  // --laser-pose X Y YAW
};

// The import's options on `cmd`; `job`: for track and calibrate (their own --out, and
// --keep-dataset), else for import (--out and --force of the dataset).
void add_import_options(CLI::App* cmd, ImportFlags& f, bool job);

// The flags as the library's options: --wheel-joints split, --odometry-k when given.
recording::ImportOptions import_options(const ImportFlags& f);

// For track and calibrate: `input` imported into `out`/dataset with a progress bar and a line
// on the terminal when it is a recording; nullptr when it is a dataset folder (recording
// options given with one are warned about).
std::unique_ptr<pipeline::ImportedDataset> import_for_job(CLI::App* cmd,
                                                          const std::string& input,
                                                          const std::string& out,
                                                          const ImportFlags& f);

}  // namespace omnivert::cli
