#pragma once
// The picture of the check by eye, paper Figs. 23 and 26: reference points (a laser scan, the
// corners of a map) drawn on an omnidirectional image at their camera bearings, for one
// mounting. Each point is drawn at its bearing, at a radius that grows with its distance
// (r_min + (r_max - r_min) d / (d + 1.5 m): a polar plot of the scan, not the camera's
// projection); each corner, where a vertical edge stands, as a red radial tick inside the
// inner and outside the outer circle of the annulus, and the extracted lines in cyan across
// the annulus: when the mounting is right, the ticks continue the cyan lines.

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "omnivert/core/mirror_circle.hpp"

namespace omnivert::viz {

struct ReprojectionLayer {
  std::string title;                     // drawn at the top, '\n' between lines
  std::vector<Eigen::Vector2d> points;   // (camera bearing [rad], distance [m])
  std::vector<Eigen::Vector2d> corners;  // (camera bearing [rad], distance [m])
  std::vector<bool> matched;             // per corner: an extracted line within the gate
  std::vector<Eigen::Vector2d> ends;     // a scan's ends, drawn as corners with thin ticks
  std::vector<bool> ends_matched;
};

// One panel: the image (grey or BGR) with the lines (camera bearings [rad]) and the layer.
// `bearing_sign` maps bearings to image angles (docs/theory/conventions.md).
cv::Mat draw_reprojection(const cv::Mat& image,
                          const MirrorCircle& circle,
                          int bearing_sign,
                          const std::vector<double>& lines,
                          const ReprojectionLayer& layer);

// Pictures side by side (a row), rows one under the other; sizes may differ (padded black).
cv::Mat hconcat_pictures(const std::vector<cv::Mat>& pictures);
cv::Mat vconcat_pictures(const std::vector<cv::Mat>& pictures);

}  // namespace omnivert::viz
