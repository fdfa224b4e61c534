// omnivert reproject DATASET --extrinsics FILE: the check by eye of a mounting (paper Sec. 9.2,
// Figs. 23 and 26): a reference's corners drawn on chosen frames with a mounting before and
// the given one after, and the median corner-to-line bearing offset.

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include "check_options.hpp"
#include "commands.hpp"
#include "core/progress.hpp"
#include "core/yaml_fields.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/image/image_io.hpp"
#include "omnivert/pipeline/reprojection.hpp"
#include "pipeline_options.hpp"

namespace omnivert::cli {

namespace {

struct ReprojectArgs {
  std::string dataset;
  std::string extrinsics;  // after
  std::string before;      // empty: the paper's hand measurement (0, 0.2 m, 0)
  std::string out = "reprojection.png";
  CheckFlags check;
  FeaturePipelineOptions pipeline;
  std::string mask;
};

// phi, rho, psi of a YAML file (extrinsics.yaml of calibrate, ground_truth/extrinsics.yaml).
calib::Extrinsics read_mounting(const std::string& path) {
  const YAML::Node y = yaml::load_file(path);
  return {yaml::required_number(y, "phi", path),
          yaml::required_number(y, "rho", path, true),
          yaml::required_number(y, "psi", path)};
}

void run_reproject(const ReprojectArgs& a) {
  namespace fs = std::filesystem;
  const calib::Extrinsics after = read_mounting(a.extrinsics);
  const calib::Extrinsics before = a.before.empty() ? calib::Extrinsics{} : read_mounting(a.before);
  dataset::LoadOptions lo;
  lo.require_wheel = false;
  lo.allow_missing_images = true;
  const auto data = dataset::Dataset::load(a.dataset, lo);
  pipeline::ReprojectionOptions o = check_options(a.check);
  o.features = a.pipeline;
  o.mask = a.mask;
  std::string why;
  if (!o.IsValid(&why)) throw InputError("invalid options: " + why);
  if (a.check.reference == "none") throw InputError("--reference none: nothing to draw");
  if (a.check.reference == "auto") {
    std::error_code ec;
    const fs::path root(a.dataset);
    if (fs::is_directory(root / "laser0", ec))
      o.reference.source = pipeline::ReferenceSource::kLaser;
    else if (fs::exists(root / "ground_truth" / "edges.csv", ec))
      o.reference.source = pipeline::ReferenceSource::kMap;
    else
      throw InputError(
          a.dataset,
          0,
          "no laser0/ and no ground_truth/edges.csv: give --reference FILE.csv, "
          "a list of vertical corners (docs/calibration.md#checking-the-result-by-eye)");
  }
  const pipeline::References refs = pipeline::load_references(data, o.reference);
  std::optional<Progress> bar;
  o.progress = [&bar](std::size_t done, std::size_t total) {
    if (!bar) bar.emplace("extract", total);
    bar->update(done);
  };
  const pipeline::ReprojectionResult r =
      pipeline::check_reprojection(data, refs, {}, before, after, o);
  if (bar) bar->finish();
  write_image_atomic(a.out, r.picture);
  std::printf("%s\n%s\nwrote %s\n", r.description.c_str(), r.message().c_str(), a.out.c_str());
}

}  // namespace

void add_reproject_command(CLI::App& app) {
  auto a = std::make_shared<ReprojectArgs>();
  CLI::App* cmd = app.add_subcommand(
      "reproject",
      "Draw a laser scan's (or a map's) corners on the images with a mounting, before and "
      "after, and measure their bearing offset to the extracted lines (paper Figs. 23, 26)");
  cmd->add_option(
         "DATASET", a->dataset, "Dataset folder (cam0/; laser0/, wheel0/ or ground_truth/)")
      ->required();
  cmd->add_option("--extrinsics",
                  a->extrinsics,
                  "The mounting drawn on the right: a YAML file with phi, rho, psi (an "
                  "extrinsics.yaml of calibrate)")
      ->required();
  cmd->add_option("--before",
                  a->before,
                  "The mounting drawn on the left (default: phi 0, rho 0.2 m, psi 0, the "
                  "paper's hand measurement)");
  cmd->add_option("--out", a->out, "The picture to write (PNG)")->capture_default_str();
  add_check_options(cmd, a->check, "--");
  add_pipeline_options(cmd, a->pipeline);
  add_mask_option(cmd, a->mask);
  cmd->callback([a] { run_reproject(*a); });
}

}  // namespace omnivert::cli
