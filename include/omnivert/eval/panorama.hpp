#pragma once
// The cylindrical panorama of a catadioptric image (the paper's Fig. 10) and the rectangular
// patterns that SSD and ZNCC compare in Sec. 5.
//
// Geometry (docs/theory/conventions.md): column c holds camera bearing beta = 2 pi c / width (c = 0
// is bearing 0, bearings grow with c); the image angle is a = bearing_sign * beta. Row i holds
// radius r = r_max - i (r_max - r_min) / (rows - 1): the rim (highest elevation for the usual
// mirror) on top, the camera's reflection at the bottom. Each panorama pixel is the bilinear
// interpolation of the image at (c_x + r cos a, c_y + r sin a); outside the image it is 0.

#include <opencv2/core.hpp>

#include "omnivert/core/mirror_circle.hpp"

namespace omnivert::eval {

struct PanoramaOptions {
  // Columns for 360 degrees. 0: a multiple of 360 close to the circumference at the middle
  // radius, 2 pi (r_min + r_max) / 2, so one column is about one pixel of arc there and whole
  // degrees fall on columns.
  int width = 0;
  // Rows from r_max to r_min. 0: round(r_max - r_min) + 1 (one pixel per row).
  int rows = 0;
  int bearing_sign = 1;  // +1: beta = a, -1: beta = -a (mirror-flipped image)
};

struct Panorama {
  cv::Mat1f image;  // rows x width, grey levels of the source image
  MirrorCircle circle;
  int bearing_sign = 1;

  int width() const { return image.cols; }
  int rows() const { return image.rows; }
  // Column (fractional) of a camera bearing [rad], in [0, width).
  double column_of_bearing(double bearing) const;
  // Camera bearing [rad] of a (fractional) column, wrapped to (-pi, pi].
  double bearing_of_column(double column) const;
  // Radius [px] of a (fractional) row.
  double radius_of_row(double row) const;
  // Pixels of arc per column at radius r.
  double arc_per_column(double r) const;
};

// Unwraps the annulus circle.r_min..circle.r_max of an image (8-bit or float, 1 channel; a
// colour image is converted to grey) into a panorama. Throws std::invalid_argument for an
// empty image or an annulus with r_min >= r_max or r_min < 0.
Panorama unwrap_panorama(const cv::Mat& image,
                         const MirrorCircle& circle,
                         const PanoramaOptions& options = {});

// The rectangular pattern of Sec. 5 (Fig. 10): all rows of the panorama, `width_columns`
// columns centred on the column of `bearing` (linear interpolation between columns, wrapping
// around 360 degrees). width_columns >= 1.
cv::Mat1f panorama_pattern(const Panorama& panorama, double bearing, int width_columns);

// Pattern width in columns for the paper's win = 2 r_a (Sec. 5), r_a = (r_max - r_min) / 6,
// measured as arc at the middle radius.
int paper_pattern_columns(const Panorama& panorama);

// Mean squared difference of two patterns of the same size (SSD divided by the pixel count,
// so patterns of different sizes compare on one scale). 0 for identical patterns.
double ssd_per_pixel(const cv::Mat1f& a, const cv::Mat1f& b);

// Zero-mean normalised cross-correlation of two patterns of the same size, in [-1, 1]; 1 for
// identical (or affinely brighter) patterns. 0 when either pattern is flat (no variance).
double zncc(const cv::Mat1f& a, const cv::Mat1f& b);

}  // namespace omnivert::eval
