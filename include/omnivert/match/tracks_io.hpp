#pragma once
// tracks.csv: the tracker's output, one row per reported line per frame (drawn as the paper's
// Fig. 22 by tracks_plot.hpp).
//
// Columns (header line first; only the first four are required when reading):
//   frame          0-based image index in the dataset (cam0/data.csv order)
//   timestamp_ns   image timestamp
//   track_id       stable integer id, 0, 1, 2, ... in order of creation
//   bearing_rad    camera bearing beta in (-pi, pi] (docs/theory/conventions.md)
//   image_angle_rad, edge_pixels, r_inner, r_outer   the detection (extract/vertical_line.hpp)
//   matched_frame  frame of the observation this one was matched to; -1 starts a new track
//   distance       descriptor distance of that match (eq. 6); 0 for a new track
//   line, matched_line, crowded   see TrackRow
//   annulus_fraction   edge_pixels / (R_max - R_min): the calibration uses the bearings of
//                  lines at least DatasetRunOptions::min_annulus_fraction long; -1: not known

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "omnivert/describe/frame_features.hpp"
#include "omnivert/match/tracker.hpp"

namespace omnivert {

struct TrackRow {
  std::int64_t frame = 0;
  std::int64_t timestamp_ns = 0;
  std::int64_t track_id = 0;
  double bearing = 0.0;
  double image_angle = 0.0;
  int edge_pixels = 0;
  double r_inner = 0.0;
  double r_outer = 0.0;
  std::int64_t matched_frame = -1;
  double distance = 0.0;
  // Index of this line among its frame's lines, and of the line it was matched to among the
  // lines of matched_frame (-1: unknown, or a new track). They identify a link exactly even
  // when a track holds two lines in one frame (the paper's rules allow such double claims).
  int line = -1;
  int matched_line = -1;
  // VerticalLine::crowded: another edge runs within a few pixels all along this line.
  bool crowded = false;
  // VerticalLine::annulus_fraction; NaN when not known (a file without the column): such a
  // bearing is used by the calibration whatever its length.
  double annulus_fraction = std::numeric_limits<double>::quiet_NaN();
  // The line of the file it was read from (read_tracks_csv; 0: not read from a file), for
  // messages about it. Not written.
  int source_line = 0;
};

// Appends one row per line of `frame` (in line order) from the tracker's assignments.
void append_track_rows(std::int64_t frame_index,
                       std::int64_t timestamp_ns,
                       const FrameFeatures& frame,
                       const std::vector<TrackAssignment>& assignments,
                       std::vector<TrackRow>* rows);

// Writes tracks.csv. The file is written under a temporary name and renamed when complete,
// so a failed run never leaves a partial file that looks complete. Throws InputError when the
// file cannot be written.
void write_tracks_csv(const std::filesystem::path& path, const std::vector<TrackRow>& rows);

// Reads tracks.csv (columns found by header name, any order; unknown columns ignored).
// Throws InputError(file, line, problem) for a missing file, a missing required column, a
// malformed or non-finite number, a negative frame or track id.
std::vector<TrackRow> read_tracks_csv(const std::filesystem::path& path);

}  // namespace omnivert
