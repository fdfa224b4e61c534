#pragma once
// A world vertical line as seen in one catadioptric frame: a radial segment of the image
// (Sec. 2). All angles in radians.

namespace omnivert {

struct VerticalLine {
  // Image angle of the radial line, a = atan2(v - cy, u - cx), refined below the 0.5 degree
  // sector (NOTES Sec. 2), in (-pi, pi].
  double image_angle = 0.0;
  // Camera bearing, beta = bearing_sign * a (NOTES Sec. 1), in (-pi, pi].
  double bearing = 0.0;
  // Number of 1-pixel radial steps of the annulus that hold an edge pixel of this line.
  int edge_pixels = 0;
  // Radial extent of the supporting edge pixels, in pixels from the mirror centre.
  double r_inner = 0.0;
  double r_outer = 0.0;
  // RMS lateral distance of the supporting edge pixels from the fitted radial line, in pixels.
  double fit_rms_px = 0.0;
};

}  // namespace omnivert
