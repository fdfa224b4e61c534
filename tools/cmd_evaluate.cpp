// omnivert evaluate DATASET DIR: the tracks of DIR/tracks.csv against the dataset's ground
// truth, as the paper's Table 3 (docs/tracking.md gives the rules).

#include <cstdio>
#include <filesystem>
#include <memory>

#include <spdlog/spdlog.h>

#include "commands.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/eval/tracking_eval.hpp"
#include "omnivert/image/image_io.hpp"

namespace omnivert::cli {

void add_evaluate_command(CLI::App& app) {
  struct Args {
    std::string dataset, dir;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate", "Compare DIR/tracks.csv with the dataset's ground truth (the paper's Table 3)");
  cmd->add_option("DATASET", a->dataset, "Dataset folder with ground_truth/lines.csv")->required();
  cmd->add_option("DIR", a->dir, "Folder holding tracks.csv (from omnivert track)")->required();
  cmd->callback([a] {
    namespace fs = std::filesystem;
    dataset::LoadOptions lo;
    lo.require_wheel = false;
    lo.allow_missing_images = true;  // tracks of a dataset with a missing frame are evaluated
    const auto data = dataset::Dataset::load(a->dataset, lo);
    for (const std::string& n : data.notes()) spdlog::debug("{}", n);
    if (!data.ground_truth_error().empty()) throw InputError(data.ground_truth_error());
    const auto& gt = data.ground_truth();
    if (!gt || !gt->has_lines)
      throw InputError((fs::path(a->dataset) / "ground_truth/lines.csv").string(),
                       0,
                       "file not found: evaluation needs the ground-truth lines");
    const auto& cam = data.camera();
    if (!cam.r_min || !cam.r_max)
      throw InputError((fs::path(a->dataset) / "cam0/sensor.yaml").string(),
                       0,
                       "r_min and r_max are needed to tell long lines (>= 60% of the annulus)");
    std::vector<eval::GroundTruthLine> truth;
    truth.reserve(gt->lines.size());
    for (const auto& l : gt->lines)
      truth.push_back({l.frame, l.line_id, l.bearing, l.r_inner, l.r_outer});
    const auto rows = read_tracks_csv(fs::path(a->dir) / "tracks.csv");
    eval::TrackingEvalOptions o;
    o.annulus_r_min = *cam.r_min;
    o.annulus_r_max = *cam.r_max;
    o.num_frames = static_cast<std::int64_t>(data.size());
    std::vector<eval::OccluderBearing> occluders;  // the people the simulator drew, if any
    for (const auto& e : gt->occluders) occluders.push_back({e.frame, e.bearing});
    const auto ev = eval::evaluate_tracking(rows, truth, o, occluders);
    const std::string table = eval::format_tracking_table(ev);
    std::printf("%s", table.c_str());
    const fs::path txt = fs::path(a->dir) / "evaluation.txt";
    write_text_atomic(txt.string(), table);
    std::printf("wrote %s\n", txt.c_str());
  });
}

}  // namespace omnivert::cli
