// omnivert camera IMAGES_OR_DATASET...: mirror centre, rim, annulus and a proposed mask of a
// new camera from many frames, written as cam0/sensor.yaml (docs/getting-started.md).

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/core/file_io.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/extract/camera_estimate.hpp"
#include "omnivert/image/image_io.hpp"
#include "omnivert/viz/overlay.hpp"

namespace omnivert::cli {

namespace {

namespace fs = std::filesystem;

struct CameraArgs {
  std::vector<std::string> inputs;
  std::string out;
  std::string overlay;
  std::string mask_out;
  int max_frames = 0;
};

// The image files of a dataset folder, in the order of cam0/data.csv (docs/dataset-format.md).
std::vector<std::string> dataset_images(const fs::path& dir) {
  const fs::path csv = dir / "cam0" / "data.csv";
  std::ifstream in(csv);
  if (!in) {
    throw InputError(
        dir.string(), 0, "is a folder without cam0/data.csv: give image files or a dataset folder");
  }
  std::vector<std::string> files;
  std::string row;
  int line = 0;
  while (std::getline(in, row)) {
    ++line;
    if (!row.empty() && row.back() == '\r') row.pop_back();
    if (row.find_first_not_of(" \t") == std::string::npos || row[0] == '#') continue;
    const auto comma = row.find(',');
    if (comma == std::string::npos)
      throw InputError(csv.string(), line, "expected 'timestamp,filename'");
    std::string name = row.substr(comma + 1);
    name.erase(0, name.find_first_not_of(" \t"));
    name.erase(name.find_last_not_of(" \t") + 1);
    if (name.empty()) throw InputError(csv.string(), line, "empty file name");
    files.push_back((dir / "cam0" / "data" / name).string());
  }
  if (files.empty()) throw InputError(csv.string(), 0, "lists no images");
  return files;
}

void run_camera(const CameraArgs& a) {
  std::vector<std::string> files;
  for (const auto& in : a.inputs) {
    if (fs::is_directory(in)) {
      const auto d = dataset_images(in);
      files.insert(files.end(), d.begin(), d.end());
    } else {
      files.push_back(in);
    }
  }
  if (a.max_frames > 0 && static_cast<int>(files.size()) > a.max_frames) {
    // An even subsample over the whole sequence (the robot's motion is what a mask needs).
    std::vector<std::string> sub;
    for (int i = 0; i < a.max_frames; ++i)
      sub.push_back(files[static_cast<std::size_t>(i) * files.size() / a.max_frames]);
    files.swap(sub);
  }
  std::vector<cv::Mat> frames;
  for (const auto& f : files) {
    cv::Mat gray;
    FeaturePipeline::to_gray8(read_image(f), gray);
    if (!frames.empty() && gray.size() != frames[0].size()) {
      throw InputError(f,
                       0,
                       "image is " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows) +
                           " but the first one is " + std::to_string(frames[0].cols) + "x" +
                           std::to_string(frames[0].rows) + ": one camera, one image size");
    }
    frames.push_back(gray.clone());
  }
  const CameraEstimate e = estimate_camera(frames);

  std::printf(
      "%5s %10s %10s %9s %8s %8s  %s\n", "frame", "cx", "cy", "rim", "r_min", "r_max", "file");
  for (std::size_t i = 0; i < e.frames.size(); ++i) {
    const auto& f = e.frames[i];
    if (f.found) {
      std::printf("%5zu %10.2f %10.2f %9.2f %8.1f %8.1f  %s%s\n",
                  i,
                  f.circle.center.x(),
                  f.circle.center.y(),
                  f.circle.rim_radius,
                  f.circle.r_min,
                  f.circle.r_max,
                  files[i].c_str(),
                  f.inlier ? "" : "  (outlier, not used)");
    } else {
      std::printf("%5zu %10s %10s %9s %8s %8s  %s  (no rim: %s)\n",
                  i,
                  "-",
                  "-",
                  "-",
                  "-",
                  "-",
                  files[i].c_str(),
                  f.why.c_str());
    }
  }
  const auto& c = e.circle;
  std::printf("camera: %dx%d, centre (%.2f, %.2f) px, rim %.2f px, annulus %.1f..%.1f px\n",
              e.width,
              e.height,
              c.center.x(),
              c.center.y(),
              c.rim_radius,
              c.r_min,
              c.r_max);
  std::printf(
      "frames: %zu, rim found on %zu, joint fit on %d (%d rim points, rms %.2f px); "
      "spread of the per-frame centres %.2f px\n",
      e.frames.size(),
      static_cast<std::size_t>(
          std::count_if(e.frames.begin(), e.frames.end(), [](const auto& f) { return f.found; })),
      e.used_frames,
      e.rim_points,
      e.rim_rms_px,
      e.spread_px);

  std::string mask_entry;
  if (e.mask.empty()) {
    std::printf("%s\n", e.mask_note.c_str());
  } else if (a.mask_out.empty()) {
    std::printf(
        "a mask was proposed (%.1f%% of the annulus excluded); give --mask-out FILE.png "
        "to write it\n",
        100 * e.masked_fraction);
  } else {
    write_image_atomic(a.mask_out, e.mask);
    const fs::path yaml_dir = fs::absolute(a.out).parent_path();
    mask_entry = fs::absolute(a.mask_out).lexically_relative(yaml_dir).generic_string();
    std::printf("mask written to %s (%.1f%% of the annulus excluded)\n",
                a.mask_out.c_str(),
                100 * e.masked_fraction);
  }
  const std::string provenance =
      "estimated by `omnivert camera` from " + std::to_string(frames.size()) + " frame(s)";
  write_text_atomic(a.out, camera_sensor_yaml(e, mask_entry, provenance));
  std::printf("sensor.yaml written to %s\n", a.out.c_str());
  if (!a.overlay.empty()) {
    write_image_atomic(a.overlay, viz::draw_camera_overlay(frames[frames.size() / 2], e));
    std::printf("overlay written to %s\n", a.overlay.c_str());
  }
}

}  // namespace

void add_camera_command(CLI::App& app) {
  auto args = std::make_shared<CameraArgs>();
  CLI::App* cmd = app.add_subcommand(
      "camera",
      "A new camera from many frames: mirror centre, rim, annulus (and a mask of what never "
      "changes), written as cam0/sensor.yaml");
  cmd->add_option("IMAGES_OR_DATASET",
                  args->inputs,
                  "Image files, or dataset folders (cam0/data.csv and cam0/data/)")
      ->required();
  cmd->add_option("--out", args->out, "sensor.yaml to write (atomically)")->required();
  cmd->add_option(
      "--overlay", args->overlay, "Write a picture of the rim, centre, annulus and masked pixels");
  cmd->add_option("--mask-out",
                  args->mask_out,
                  "Write the proposed mask (PNG, non-zero = usable) when the frames show motion");
  cmd->add_option("--max-frames",
                  args->max_frames,
                  "Use at most N frames, evenly spread over the sequence (0: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([args] { run_camera(*args); });
}

}  // namespace omnivert::cli
