#pragma once
// Synthetic catadioptric-like test images with radial edges at known angles: the mirror rim
// (dark outside), the camera's self-reflection (dark disc inside r_min), sectors of different
// grey levels separated by full-length radial edges, and patches (doors, posters) whose two
// radial edges cover only part of the annulus. Anti-aliased by supersampling the pixels that
// a boundary crosses, so every edge lies at its exact sub-pixel angle.
//
// The ground truth (edge angles, radial extents inside the annulus, the circle) is exact by
// construction; the extraction tests and the demo use it.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/core/mirror_circle.hpp"

namespace omnivert::sim {

struct RadialPatternOptions {
  int width = 640;
  int height = 480;
  double center_jitter = 10.0;  // centre uniformly within +-jitter of the image centre, px
  double r_min = 40.0;
  double r_max = 220.0;
  double rim_radius = 228.0;   // mirror boundary, just outside r_max
  int full_edges = 12;         // sector boundaries (full-length edges)
  int patches = 5;             // each adds two partial-length edges
  double min_contrast = 20.0;  // grey levels across an edge
  double max_contrast = 120.0;
  double min_separation_deg = 4.0;  // between any two edges
  double noise_sigma = 3.0;         // Gaussian image noise, grey levels
  bool texture = true;              // low-contrast blobs so descriptors differ between lines
  // The same scene rotated about the mirror centre: every image angle + rotation (the image
  // noise is drawn afresh, as a rotated camera would see it).
  double rotation_rad = 0.0;
  // Seed of the image noise (0: follow `seed`).
  std::uint64_t noise_seed = 0;
  std::uint64_t seed = 1;
};

struct RadialEdgeTruth {
  double image_angle;  // radians, (-pi, pi]
  double r_from;       // radial extent inside the annulus, px
  double r_to;
  bool full;  // a sector boundary spanning the whole annulus
};

struct RadialPattern {
  cv::Mat image;  // CV_8UC1
  MirrorCircle circle;
  std::vector<RadialEdgeTruth> edges;
};

RadialPattern draw_radial_pattern(const RadialPatternOptions& options);

}  // namespace omnivert::sim
