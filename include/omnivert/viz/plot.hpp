#pragma once
// Pictures of the descriptor study (docs/study.md): similarity matrices as heat maps with a
// colour scale (the paper's Figs. 9, 11, 12) and x-y plots with axes, ticks, labels and a
// legend (Figs. 13-18). Plain OpenCV drawing; every function returns an 8-bit BGR image.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace omnivert::viz {

struct HeatmapOptions {
  std::string title;
  std::string axis_label = "bearing [deg]";  // both axes
  double axis_max = 360.0;                   // value at the last row/column
  std::string scale_label;                   // under the colour bar
  // Colour range; when lo >= hi, the 1st and 99th percentiles of the matrix.
  double lo = 0.0, hi = 0.0;
  int cell = 2;  // pixels per matrix cell
};

// Low values dark (most similar: the paper's convention), high values bright; a colour bar
// on the right with its scale.
cv::Mat draw_heatmap(const cv::Mat1f& matrix, const HeatmapOptions& options);

struct PlotSeries {
  std::string name;  // empty: not in the legend
  std::vector<double> x, y;
  cv::Scalar color;     // BGR
  bool markers = true;  // a dot at every point
  bool dashed = false;
};

struct PlotOptions {
  std::string title, x_label, y_label;
  int width = 900, height = 600;
  // Axis ranges; when lo >= hi, taken from the data (with a margin).
  double x_lo = 0, x_hi = 0, y_lo = 0, y_hi = 0;
  std::vector<double> vertical_lines;        // drawn grey, dashed (thresholds)
  std::vector<std::string> vertical_labels;  // written at the bottom of each line
  bool legend_bottom = false;                // legend box bottom right instead of top right
  bool log_y = false;  // logarithmic y axis (y_lo, y_hi in data units; values <= 0 left out)
};

cv::Mat draw_plot(const std::vector<PlotSeries>& series, const PlotOptions& options);

// A distinct colour for series i.
cv::Scalar plot_color(int i);

}  // namespace omnivert::viz
