#pragma once
// The tilt of the mirror axis, measured from the vertical lines themselves, and the image
// rectified to an upright camera (docs/theory/tilt.md).
//
// Geometry. With the mirror axis tilted by t towards the camera bearing d (core/tilt.hpp), a
// world vertical line is no radial image line: its pixels, lifted to viewing directions s in
// the camera frame C through the projection r(el) of the unified model, rotated into the
// upright frame (s_V = R_VC(t, d) s), all have the same azimuth atan2(s_V.y, s_V.x), the
// line's bearing b of eq. (16)-(17). In the image the line is a conic arc through the image
// of the nadir, v = c + gamma sin t / (xi + cos t) (cos d, sin d) (for bearing_sign +1), and
// to first order in t its pixels lie off the radial line of angle b by
//     r tan(el(r)) t sin(b - d)   [px],
// zero at the horizon (el = 0), of opposite sign inside and outside it.
//
// Estimate. The unknowns are the tilt vector x = t (cos d, sin d). For each line j and each
// of its edge pixels i the residual is e_ij = r_i wrap(az(R(x) s_i) - b_j) [px, tangential],
// with b_j the mean azimuth of the line's pixels (eliminated: variable projection).
// Gauss-Newton on x over all lines of all frames added, a central-difference Jacobian, and
// pixels farther than the inlier bound from their line's curve left out. Needs the camera's
// xi and gamma (CameraGeometry::has_projection()).

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/core/mirror_circle.hpp"
#include "omnivert/core/vertical_line.hpp"
#include "omnivert/extract/line_extractor.hpp"

namespace omnivert {

struct TiltEstimate {
  bool valid = false;                                // enough lines, a solvable system
  Eigen::Vector2d vector = Eigen::Vector2d::Zero();  // t (cos d, sin d) [rad]
  double sigma = 0.0;                                // standard deviation of t [rad] (formal)
  int frames = 0;
  int lines = 0;        // lines used (with enough inlier pixels)
  int pixels = 0;       // inlier edge pixels
  double rms_px = 0.0;  // tangential RMS of the inliers about their curves [px]

  double tilt() const { return vector.norm(); }  // t [rad]
  double direction() const;                      // d, camera bearing [rad], (-pi, pi]
  double tilt_deg() const;
  double direction_deg() const;
  // One line for people: "tilt 2.03 deg (+-0.02) towards bearing 44.8 deg, from 312 lines".
  std::string describe() const;
};

struct TiltEstimatorOptions {
  // An edge pixel belongs to a line when it is nearer than this to the line's curve [px]:
  // wide first (the radial line misses the curve by up to ~4 px at 3 degrees), then narrow.
  double corridor_px = 4.5;
  // 0.6 px: on rendered frames 1 px let texture pixels in (residual RMS 0.34 px against
  // 0.22 px) and pulled an upright camera's estimate to 0.1 degree.
  double inlier_px = 0.6;
  int min_line_pixels = 20;  // a line with fewer inlier pixels is left out
  int min_lines = 4;         // fewer lines in all: no estimate
  int iterations = 8;
  // Tilts above this are worth a warning: the bearings of unrectified radial lines are then
  // off by up to several tenths of a degree (docs/validation.md#tilt).
  double warn_deg = 0.5;

  bool IsValid(std::string* why) const;
};

class TiltEstimator {
 public:
  TiltEstimator(CameraGeometry geometry, TiltEstimatorOptions options = {});

  // Adds one frame: the thinned edge pixels of LineExtractor::last_edge_points(), the circle
  // they were extracted with, and the lines found. Each edge pixel goes to the nearest line
  // of its polarity within corridor_px.
  void add_frame(const std::vector<LineExtractor::EdgePoint>& edges,
                 const MirrorCircle& circle,
                 const std::vector<VerticalLine>& lines);

  // The estimate over all frames added so far.
  TiltEstimate estimate() const;

  const TiltEstimatorOptions& options() const { return options_; }

 private:
  struct Line {
    std::vector<Eigen::Vector3d> s;  // viewing directions in the camera frame
    std::vector<double> r;           // radius [px]
  };
  // Residuals (tangential pixels) of every pixel at tilt vector x; b_j from the inliers of
  // `inlier` (or all pixels when it is empty).
  void residuals(const Eigen::Vector2d& x,
                 const std::vector<std::vector<char>>& inlier,
                 std::vector<std::vector<double>>& e) const;

  CameraGeometry geometry_;
  TiltEstimatorOptions options_;
  std::vector<Line> lines_;
  int frames_ = 0;
};

// The upright image of a tilted camera: each pixel of the output takes the value (bicubic)
// of the input at the pixel of its viewing direction rotated into the camera frame, s_C =
// R_VC(x)^T s_V. Pixels outside r_min - 4 .. r_max + 4 are copied. Needs has_projection().
// The pixel maps are kept while the circle stays the same (a centre given in sensor.yaml).
class TiltRectifier {
 public:
  TiltRectifier(CameraGeometry geometry, const Eigen::Vector2d& tilt_vector);
  void apply(const cv::Mat& gray, const MirrorCircle& circle, cv::Mat& out);
  const Eigen::Vector2d& tilt_vector() const { return tilt_; }

 private:
  CameraGeometry geometry_;
  Eigen::Vector2d tilt_;
  MirrorCircle key_;
  cv::Mat1f mx_, my_;
};

// Camera bearing [rad] in the upright frame of the pixel at image angle a and radius r
// (docs/theory/tilt.md#bearing-correction); needs has_projection().
double upright_bearing(const CameraGeometry& geometry,
                       const Eigen::Vector2d& tilt_vector,
                       double image_angle,
                       double radius);

}  // namespace omnivert
