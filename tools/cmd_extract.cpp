// omnivert extract IMAGE: the vertical lines of one catadioptric image (Sec. 2-3).

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/extract/tilt_estimator.hpp"
#include "omnivert/image/grey.hpp"
#include "omnivert/image/image_io.hpp"
#include "omnivert/image/image_mask.hpp"
#include "omnivert/pipeline/tilt_check.hpp"
#include "omnivert/viz/overlay.hpp"
#include "pipeline_options.hpp"

namespace omnivert::cli {

namespace {

struct ExtractArgs {
  std::string image;
  std::string sensor;
  std::string bayer;
  int bit_depth = -1;
  bool json = false;
  std::string overlay;
  int highlight = -1;
  std::string mask;
  double xi = 0.0, gamma = 0.0;  // 0: from --sensor
  bool correct_tilt = false;
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
  if (!a.bayer.empty()) {
    const auto p = parse_bayer_pattern(a.bayer);
    if (!p) throw InputError("--bayer " + a.bayer + ": expected RGGB, BGGR, GRBG, GBRG or none");
    geometry.pixel_format.bayer = *p;
  }
  if (a.bit_depth >= 0) geometry.pixel_format.bit_depth = a.bit_depth;
  if (!a.mask.empty()) {
    // Without --sensor the mask gives the size the image must have.
    geometry.mask = a.mask;
    if (geometry.width == 0) {
      const cv::Mat m = read_mask(a.mask);
      geometry.width = m.cols;
      geometry.height = m.rows;
    }
  }
  if (a.xi > 0.0) geometry.xi = a.xi;
  if (a.gamma > 0.0) geometry.gamma = a.gamma;
  const pipeline::TiltCheckOptions check;
  const TiltEstimate tilt = pipeline::measure_image_tilt(image, geometry, a.pipeline, check);
  FeaturePipelineOptions po = a.pipeline;
  const bool corrected = a.correct_tilt && tilt.valid && tilt.tilt_deg() > check.correct_deg;
  if (corrected) po.tilt = tilt.vector;
  FeaturePipeline pipe(geometry, po);
  FrameFeatures f;
  if (!pipe.process(image, f, &why)) throw InputError(a.image, 0, why);
  const std::string warning = pipeline::tilt_warning(tilt, check, corrected);
  if (!warning.empty()) std::fprintf(stderr, "warning: %s\n", warning.c_str());

  if (a.json) {
    nlohmann::json j;
    j["center"] = {f.circle.center.x(), f.circle.center.y()};
    j["r_min"] = f.circle.r_min;
    j["r_max"] = f.circle.r_max;
    if (tilt.valid) {
      j["tilt"] = {{"tilt_deg", tilt.tilt_deg()},
                   {"direction_deg", tilt.direction_deg()},
                   {"sigma_deg", rad2deg(tilt.sigma)},
                   {"lines", tilt.lines},
                   {"rms_px", tilt.rms_px},
                   {"corrected", corrected}};
    }
    j["lines"] = nlohmann::json::array();
    for (std::size_t i = 0; i < f.lines.size(); ++i) {
      const auto& l = f.lines[i];
      nlohmann::json jl;
      jl["bearing"] = l.bearing;
      jl["image_angle"] = l.image_angle;
      jl["edge_pixels"] = l.edge_pixels;
      jl["annulus_fraction"] = l.annulus_fraction;
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
    if (geometry.has_projection()) {
      std::printf("%s%s\n", tilt.describe().c_str(), corrected ? "; bearings upright" : "");
    }
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
    cv::Mat grey;  // the picture the lines were found in (a Bayer mosaic demosaiced)
    to_grey8(image, geometry.pixel_format, grey, nullptr);
    write_image_atomic(a.overlay,
                       viz::draw_overlay(grey, f, pipe.descriptor_extractor(), a.highlight));
    if (!a.json) std::printf("overlay written to %s\n", a.overlay.c_str());
  }
}

}  // namespace

void add_extract_command(CLI::App& app) {
  auto args = std::make_shared<ExtractArgs>();
  CLI::App* cmd = app.add_subcommand(
      "extract", "Vertical lines of one catadioptric image: centre, lines, bearings, descriptors");
  cmd->add_option("IMAGE",
                  args->image,
                  "Image file (PNG, JPEG, TIFF, ...; grey or colour, 8 or 16 bits, or a raw "
                  "Bayer mosaic with --bayer)")
      ->required();
  cmd->add_option("--sensor",
                  args->sensor,
                  "cam0/sensor.yaml: resolution, optional center, r_min, r_max, bearing_sign, "
                  "bayer, bit_depth");
  cmd->add_option("--bayer",
                  args->bayer,
                  "The image is a raw Bayer mosaic with this pattern (RGGB, BGGR, GRBG, GBRG; "
                  "none: grey or colour); overrides sensor.yaml's bayer");
  cmd->add_option("--bit-depth",
                  args->bit_depth,
                  "Significant bits of a 16-bit image (e.g. 12 for values 0..4095; 0: the full "
                  "16 bits); overrides sensor.yaml's bit_depth")
      ->check(CLI::IsMember({0, 9, 10, 11, 12, 13, 14, 15, 16}));
  cmd->add_flag("--json", args->json, "Print one JSON object instead of a table");
  cmd->add_option("--overlay",
                  args->overlay,
                  "Write a picture of the centre, annulus, lines and one line's descriptor areas");
  cmd->add_option("--highlight",
                  args->highlight,
                  "Line whose descriptor areas the overlay draws (default: the longest)");
  cmd->add_option("--xi", args->xi, "Unified model xi, for the tilt measurement (else --sensor's)");
  cmd->add_option("--gamma", args->gamma, "Unified model gamma [px] (else --sensor's)");
  cmd->add_flag("--correct-tilt",
                args->correct_tilt,
                "Rectify the image to an upright camera when the measured tilt exceeds 0.25 deg");
  add_pipeline_options(cmd, args->pipeline);
  add_mask_option(cmd, args->mask);
  cmd->callback([args] { run_extract(*args); });
}

}  // namespace omnivert::cli
