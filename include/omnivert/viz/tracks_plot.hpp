#pragma once
// The paper's Fig. 22 drawn from tracks.csv rows (tracks_io.hpp).

#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/match/tracks_io.hpp"

namespace omnivert::viz {

struct TrackPlotOptions {
  int width = 1600;  // pixels
  int height = 900;  // pixels
  bool draw_ids = true;
  std::string title = "Vertical-line tracks";
};

// The paper's Fig. 22: bearing (degrees, -180..180, y axis) against frame number (x axis);
// each detection a small circle, each track a polyline in its own colour (broken where it
// crosses +-180 degrees, each piece drawn to the border), its id written where it starts.
// Returns an 8-bit BGR image.
cv::Mat draw_tracks(const std::vector<TrackRow>& rows, const TrackPlotOptions& options = {});

// draw_tracks, then PNG; written under a temporary name and renamed. Throws InputError when
// the file cannot be written.
void write_tracks_png(const std::filesystem::path& path,
                      const std::vector<TrackRow>& rows,
                      const TrackPlotOptions& options = {});

}  // namespace omnivert::viz
