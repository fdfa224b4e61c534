#pragma once
// A world vertical line as seen in one catadioptric frame: a radial segment of the image
// (Sec. 2). All angles in radians.

namespace omnivert {

struct VerticalLine {
  // Image angle of the radial line, a = atan2(v - cy, u - cx), refined below the 0.5 degree
  // sector (docs/theory/extraction.md), in (-pi, pi].
  double image_angle = 0.0;
  // Camera bearing, beta = bearing_sign * a (docs/theory/conventions.md), in (-pi, pi].
  double bearing = 0.0;
  // Length of the line in pixels: the radial extent covered by its edge pixels (short gaps
  // bridged); the paper thresholds it at 50% of R_max - R_min (Sec. 2).
  int edge_pixels = 0;
  // edge_pixels as a fraction of the annulus, R_max - R_min: the paper's length criterion
  // (Sec. 2, at least 0.5) and the calibration's choice of bearings
  // (pipeline::DatasetRunOptions::min_annulus_fraction).
  double annulus_fraction = 0.0;
  // Radial extent of the supporting edge pixels, in pixels from the mirror centre.
  double r_inner = 0.0;
  double r_outer = 0.0;
  // RMS lateral distance of the supporting edge pixels from the fitted radial line, in pixels.
  double fit_rms_px = 0.0;
  // Significance of the line, -log10 NFA (docs/theory/extraction.md#significance): the number
  // of radial lines of the image on which edge pixels of random positions would line up at
  // least this well is 10^-significance. LineThreshold::kSignificance keeps lines when it is
  // >= min_significance.
  double significance = 0.0;
  // Edge polarity: +1 if the image is brighter on the side of increasing image angle.
  int polarity = 0;
  // Another edge line runs within LineExtractorOptions::isolation_px of this one over most of
  // its length, so that their gradients overlap and the angle is pulled towards or pushed
  // from it (rendered door frames and their leaves 0.6-0.75 degree apart: 0.04-0.13 degree).
  // Left for the user to judge: the calibration uses them (leaving them out was measured and
  // not better: docs/theory/extraction.md#edges-close-to-another).
  bool crowded = false;
};

}  // namespace omnivert
