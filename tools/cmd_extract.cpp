// omnivert extract IMAGE: the vertical lines of one catadioptric image (Sec. 2-3).

#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/image/image_io.hpp"
#include "omnivert/viz/overlay.hpp"
#include "pipeline_options.hpp"

namespace omnivert::cli {

namespace {

struct ExtractArgs {
  std::string image;
  std::string sensor;
  bool json = false;
  std::string overlay;
  int highlight = -1;
  FeaturePipelineOptions pipeline;
};

void run_extract(const ExtractArgs& a) {
  std::string why;
  if (!a.pipeline.IsValid(&why)) throw InputError("invalid options: " + why);
  const cv::Mat image = read_image(a.image);
  CameraGeometry geometry;
  if (!a.sensor.empty()) {
    geometry = load_camera_geometry(a.sensor);
  }
  FeaturePipeline pipe(geometry, a.pipeline);
  FrameFeatures f;
  if (!pipe.process(image, f, &why)) throw InputError(a.image, 0, why);

  if (a.json) {
    nlohmann::json j;
    j["center"] = {f.circle.center.x(), f.circle.center.y()};
    j["r_min"] = f.circle.r_min;
    j["r_max"] = f.circle.r_max;
    j["lines"] = nlohmann::json::array();
    for (std::size_t i = 0; i < f.lines.size(); ++i) {
      const auto& l = f.lines[i];
      nlohmann::json jl;
      jl["bearing"] = l.bearing;
      jl["image_angle"] = l.image_angle;
      jl["edge_pixels"] = l.edge_pixels;
      jl["r_inner"] = l.r_inner;
      jl["r_outer"] = l.r_outer;
      jl["polarity"] = l.polarity;
      jl["crowded"] = l.crowded;
      jl["significance"] = l.significance;
      const auto row = f.descriptors.row(static_cast<Eigen::Index>(i));
      jl["descriptor"] = std::vector<float>(row.data(), row.data() + row.size());
      j["lines"].push_back(std::move(jl));
    }
    std::printf("%s\n", j.dump().c_str());
  } else {
    std::printf("%s: %dx%d, centre (%.2f, %.2f) px, annulus %.1f..%.1f px, %zu vertical lines\n",
                a.image.c_str(),
                image.cols,
                image.rows,
                f.circle.center.x(),
                f.circle.center.y(),
                f.circle.r_min,
                f.circle.r_max,
                f.lines.size());
    std::printf("%4s %12s %16s %11s %9s %9s %8s %8s %8s\n",
                "line",
                "bearing[deg]",
                "image_angle[deg]",
                "edge_pixels",
                "r_inner",
                "r_outer",
                "fit[px]",
                "crowded",
                "signif");
    for (std::size_t i = 0; i < f.lines.size(); ++i) {
      const auto& l = f.lines[i];
      std::printf("%4zu %12.3f %16.3f %11d %9.1f %9.1f %8.2f %8s %8.1f\n",
                  i,
                  rad2deg(l.bearing),
                  rad2deg(l.image_angle),
                  l.edge_pixels,
                  l.r_inner,
                  l.r_outer,
                  l.fit_rms_px,
                  l.crowded ? "yes" : "",
                  l.significance);
    }
  }
  if (!a.overlay.empty()) {
    write_image_atomic(a.overlay, draw_overlay(image, f, pipe.descriptor_extractor(), a.highlight));
    if (!a.json) std::printf("overlay written to %s\n", a.overlay.c_str());
  }
}

}  // namespace

void add_extract_command(CLI::App& app) {
  auto args = std::make_shared<ExtractArgs>();
  CLI::App* cmd = app.add_subcommand(
      "extract", "Vertical lines of one catadioptric image: centre, lines, bearings, descriptors");
  cmd->add_option("IMAGE", args->image, "Image file (PNG, JPEG, ...; grey or colour)")->required();
  cmd->add_option("--sensor",
                  args->sensor,
                  "cam0/sensor.yaml: resolution, optional center, r_min, r_max, bearing_sign");
  cmd->add_flag("--json", args->json, "Print one JSON object instead of a table");
  cmd->add_option("--overlay",
                  args->overlay,
                  "Write a picture of the centre, annulus, lines and one line's descriptor areas");
  cmd->add_option("--highlight",
                  args->highlight,
                  "Line whose descriptor areas the overlay draws (default: the longest)");
  add_pipeline_options(cmd, args->pipeline);
  cmd->callback([args] { run_extract(*args); });
}

}  // namespace omnivert::cli
