#pragma once
// Command-line options of the check by eye (pipeline/reprojection.hpp), shared by
// `omnivert calibrate` (prefixed --check-) and `omnivert reproject`.

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "omnivert/pipeline/reprojection.hpp"

namespace omnivert::cli {

struct CheckFlags {
  std::string reference = "auto";  // auto, laser, map, none or a corners CSV
  std::vector<std::size_t> frames;
  double gate_deg = 5.0;
  double max_scan_gap_s = 0.1;
};

inline void add_check_options(CLI::App* cmd, CheckFlags& f, const std::string& prefix) {
  const std::string g = "Check by eye (paper Figs. 23, 26)";
  cmd->add_option(prefix + "reference",
                  f.reference,
                  "What the corners come from: laser (laser0/), map (ground_truth/ of a "
                  "simulated dataset), a CSV of corners in the robot frame of the first image, "
                  "none, or auto (laser0/ when present)")
      ->capture_default_str()
      ->group(g);
  cmd->add_option(prefix + "frames", f.frames, "Frames drawn (default: the middle one)")
      ->delimiter(',')
      ->group(g);
  cmd->add_option(prefix + "gate",
                  f.gate_deg,
                  "A corner farther than this from every extracted line is unmatched [deg]")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 90.0))
      ->group(g);
  cmd->add_option(prefix + "max-scan-gap",
                  f.max_scan_gap_s,
                  "An image without a scan this close in time has no laser reference [s]")
      ->capture_default_str()
      ->check(kPositive)
      ->group(g);
}

// The options; `reference` is set for laser, map and a file, left for auto and none.
inline pipeline::ReprojectionOptions check_options(const CheckFlags& f) {
  pipeline::ReprojectionOptions o;
  o.gate_deg = f.gate_deg;
  o.frames = f.frames;
  o.reference.max_scan_gap_s = f.max_scan_gap_s;
  if (f.reference == "map") {
    o.reference.source = pipeline::ReferenceSource::kMap;
  } else if (f.reference != "laser" && f.reference != "auto" && f.reference != "none") {
    o.reference.source = pipeline::ReferenceSource::kCorners;
    o.reference.corners_file = f.reference;
  }
  return o;
}

}  // namespace omnivert::cli
