#pragma once
// Command-line options of the frame pipeline (extraction and descriptor), shared by every
// subcommand that reads images.

#include <cstdint>
#include <cstdio>
#include <map>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"

#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/pipeline/tilt_check.hpp"

namespace omnivert::cli {

// The help groups of these options (cmd_calibrate names them when --tracks makes them idle).
inline constexpr const char* kExtractionGroup = "Extraction (Sec. 2)";
inline constexpr const char* kDescriptorGroup = "Descriptor (Sec. 3)";

// --mask FILE: the image mask of docs/dataset-format.md#image-mask, instead of sensor.yaml's.
inline void add_mask_option(CLI::App* cmd, std::string& mask) {
  cmd->add_option("--mask",
                  mask,
                  "Image mask: a one-channel image of the camera's size, non-zero = usable pixel "
                  "(instead of the mask: of sensor.yaml)")
      ->group(kExtractionGroup);
}

// --threads N: threads of the frame pipeline (track_dataset); the result does not depend on it.
inline void add_threads_option(CLI::App* cmd, int& threads) {
  cmd->add_option("--threads",
                  threads,
                  "Threads reading and extracting frames (0: every core); the result is the same "
                  "for every count")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
}

// Frames per second of a job's frame stage, for the line printed at its end.
inline std::string throughput(std::int64_t frames, double seconds, int threads) {
  char buf[128];
  std::snprintf(buf,
                sizeof buf,
                "%lld frames in %.1f s: %.1f frames/s on %d thread%s",
                static_cast<long long>(frames),
                seconds,
                seconds > 0 ? frames / seconds : 0.0,
                threads,
                threads == 1 ? "" : "s");
  return buf;
}

// The tilt check of a dataset (docs/extraction.md, "Tilt").
inline void add_tilt_options(CLI::App* cmd, pipeline::TiltCheckOptions& o) {
  const std::string g = kExtractionGroup;
  cmd->add_flag("!--no-tilt-check",
                o.enabled,
                "Do not measure the tilt of the mirror axis before tracking")
      ->group(g);
  cmd->add_option("--tilt-correct-above",
                  o.correct_deg,
                  "Rectify the frames when the measured tilt exceeds this [deg] (90: never)")
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--tilt-deg",
                  o.given_deg,
                  "The mirror axis's tilt when known [deg]: the frames are rectified with it and "
                  "it is not measured (0: measure it)")
      ->check(CLI::Range(0.0, 29.9))
      ->group(g);
  cmd->add_option("--tilt-direction-deg",
                  o.given_direction_deg,
                  "The camera bearing the given tilt leans towards [deg]")
      ->check(CLI::Range(-360.0, 360.0))
      ->group(g);
}

inline void add_pipeline_options(CLI::App* cmd, FeaturePipelineOptions& o) {
  const std::string g = kExtractionGroup;
  static const std::map<std::string, LineThreshold> kThreshold{
      {"significant-or-long", LineThreshold::kSignificantOrLong},
      {"significance", LineThreshold::kSignificance},
      {"fraction", LineThreshold::kFractionOfAnnulus},
      {"adaptive", LineThreshold::kAdaptive},
      {"topk", LineThreshold::kTopK}};
  cmd->add_option("--line-threshold",
                  o.lines.threshold,
                  "Which lines to keep: significant-or-long (the default: either of the next "
                  "two), significance (fewer than 10^-(--min-significance) false alarms expected "
                  "among random edge pixels, a contrario), fraction (>= --length-fraction of "
                  "R_max - R_min, the paper's), adaptive (mean + 3 sigma of candidate lengths), "
                  "topk")
      ->transform(CLI::CheckedTransformer(kThreshold, CLI::ignore_case))
      ->group(g);
  cmd->add_option("--peak-window",
                  o.lines.peak_window,
                  "Line peaks: the score of a 0.5-degree sector adds the votes of this many "
                  "sectors on each side")
      ->check(CLI::Range(0, 10))
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--nms-radius",
                  o.lines.nms_radius,
                  "Line peaks: a peak's score beats those of this many sectors on each side")
      ->check(CLI::Range(1, 10))
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--length-fraction",
                  o.lines.length_fraction,
                  "Line length threshold as a fraction of the annulus")
      ->check(CLI::Range(0.01, 1.0))
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--min-significance",
                  o.lines.min_significance,
                  "Lines kept with --line-threshold significance: -log10 NFA at least this")
      ->check(CLI::Range(-10.0, 1000.0))
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--faint-min-significance",
                  o.lines.faint_min_significance,
                  "Significance lines below --min-significance need to be kept when they cover "
                  "--faint-min-fraction of the annulus (at --min-significance or above: none)")
      ->check(CLI::Range(-10.0, 1000.0))
      ->capture_default_str()
      ->group(g);
  cmd->add_option(
         "--faint-max-fit",
         o.lines.faint_max_fit_px,
         "RMS distance (px) of a faint line's support pixels from its radial line, at most")
      ->check(kPositive)
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--faint-min-fraction",
                  o.lines.faint_min_fraction,
                  "Fraction of the annulus a faint line (--faint-min-significance) must cover")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--top-k", o.lines.top_k, "Lines kept per frame with --line-threshold topk")
      ->check(kPositive)
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--gradient-threshold",
                  o.lines.gradient_threshold,
                  "Sobel magnitude of an edge pixel (4x the grey-level step)")
      ->check(kPositive)
      ->capture_default_str()
      ->group(g);
  cmd->add_flag("!--fixed-center",
                o.track_center,
                "Keep the first frame's centre instead of detecting it on every frame")
      ->group(g);
  cmd->add_flag("--refine-center",
                o.refine_given_center,
                "Fit the mirror centre to the rim (and track it, unless --fixed-center) even when "
                "cam0/sensor.yaml gives it; by default a given centre is used as it is")
      ->group(g);

  const std::string d = kDescriptorGroup;
  static const std::map<std::string, DescriptorSmoothing> kSmoothing{
      {"blur", DescriptorSmoothing::kGaussianBlur},
      {"weight", DescriptorSmoothing::kGaussianWeight}};
  static const std::map<std::string, DescriptorNormalization> kNorm{
      {"pair", DescriptorNormalization::kPerPair}, {"half", DescriptorNormalization::kPerHalf}};
  cmd->add_option(
         "--smoothing",
         o.descriptor.smoothing,
         "Gaussian window sigma_G = r_a/3 as an image blur (blur) or a vote weight (weight)")
      ->transform(CLI::CheckedTransformer(kSmoothing, CLI::ignore_case))
      ->group(d);
  cmd->add_option(
         "--normalization",
         o.descriptor.normalization,
         "Unit for normalisation and clipping: each left/right pair (pair) or each half (half)")
      ->transform(CLI::CheckedTransformer(kNorm, CLI::ignore_case))
      ->group(d);
  cmd->add_option("--bins", o.descriptor.bins, "Orientation bins per histogram")
      ->check(CLI::Range(4, 256))
      ->capture_default_str()
      ->group(d);
  cmd->add_option(
         "--areas", o.descriptor.areas, "Circular areas per line: 3 (touching) or 5 (overlapping)")
      ->check(CLI::IsMember({3, 5}))
      ->capture_default_str()
      ->group(d);
  cmd->add_option("--clip", o.descriptor.clip, "Clipping threshold after unit normalisation")
      ->check(CLI::Range(0.001, 1.0))
      ->capture_default_str()
      ->group(d);
}

}  // namespace omnivert::cli
