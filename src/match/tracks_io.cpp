#include "omnivert/match/tracks_io.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <system_error>
#include <unordered_map>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/core/file_io.hpp"

namespace omnivert {
namespace {

namespace fs = std::filesystem;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

template <typename T>
T parse_number(std::string_view s, const std::string& file, int line, const std::string& column) {
  T v{};
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || s.empty()) {
    throw InputError(
        file, line, "column '" + column + "': '" + std::string(s) + "' is not a valid number");
  }
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(v)) {
      throw InputError(file, line, "column '" + column + "': value is not finite");
    }
  }
  return v;
}

}  // namespace

void append_track_rows(std::int64_t frame_index,
                       std::int64_t timestamp_ns,
                       const FrameFeatures& frame,
                       const std::vector<TrackAssignment>& assignments,
                       std::vector<TrackRow>* rows) {
  for (std::size_t i = 0; i < frame.lines.size() && i < assignments.size(); ++i) {
    const VerticalLine& l = frame.lines[i];
    const TrackAssignment& a = assignments[i];
    TrackRow r;
    r.frame = frame_index;
    r.timestamp_ns = timestamp_ns;
    r.track_id = a.track_id;
    r.bearing = l.bearing;
    r.image_angle = l.image_angle;
    r.edge_pixels = l.edge_pixels;
    r.r_inner = l.r_inner;
    r.r_outer = l.r_outer;
    r.matched_frame = a.is_new() ? -1 : frame_index - a.frames_back;
    r.distance = a.distance;
    r.line = static_cast<int>(i);
    r.matched_line = a.is_new() ? -1 : a.matched_line;
    r.crowded = l.crowded;
    r.annulus_fraction = l.annulus_fraction;
    rows->push_back(r);
  }
}

void write_tracks_csv(const fs::path& path, const std::vector<TrackRow>& rows) {
  std::string out;
  out.reserve(rows.size() * 96 + 128);
  out +=
      "frame,timestamp_ns,track_id,bearing_rad,image_angle_rad,edge_pixels,r_inner,r_outer,"
      "matched_frame,distance,line,matched_line,crowded,annulus_fraction\n";
  char buf[256];
  for (const TrackRow& r : rows) {
    const int n = std::snprintf(buf,
                                sizeof(buf),
                                "%lld,%lld,%lld,%.9f,%.9f,%d,%.3f,%.3f,%lld,%.6f,%d,%d,%d,%.4f\n",
                                static_cast<long long>(r.frame),
                                static_cast<long long>(r.timestamp_ns),
                                static_cast<long long>(r.track_id),
                                r.bearing,
                                r.image_angle,
                                r.edge_pixels,
                                r.r_inner,
                                r.r_outer,
                                static_cast<long long>(r.matched_frame),
                                r.distance,
                                r.line,
                                r.matched_line,
                                r.crowded ? 1 : 0,
                                std::isfinite(r.annulus_fraction) ? r.annulus_fraction : -1.0);
    out.append(buf, static_cast<std::size_t>(n));
  }
  write_text_atomic(path.string(), out);
}

std::vector<TrackRow> read_tracks_csv(const fs::path& path) {
  const std::string file = path.string();
  if (const std::string why = unreadable_file_reason(file); !why.empty()) {
    throw InputError(file, 0, why);
  }
  std::ifstream f(path);
  if (!f) throw InputError(file, 0, "cannot open (missing file?)");
  std::string text;
  int line_no = 0;
  std::unordered_map<std::string, int> col;
  std::vector<TrackRow> rows;
  bool have_header = false;
  while (std::getline(f, text)) {
    ++line_no;
    std::string_view line = trim(text);
    if (line.empty()) continue;
    if (!have_header) {
      if (line.front() == '#') line.remove_prefix(1);
      const auto names = split(line);
      for (int i = 0; i < static_cast<int>(names.size()); ++i) {
        if (!col.emplace(std::string(names[i]), i).second) {
          throw InputError(
              file, line_no, "column '" + std::string(names[i]) + "' appears twice in the header");
        }
      }
      for (const char* required : {"frame", "timestamp_ns", "track_id", "bearing_rad"}) {
        if (!col.count(required)) {
          throw InputError(file,
                           line_no,
                           std::string("header lacks the column '") + required +
                               "' (expected frame,timestamp_ns,track_id,"
                               "bearing_rad,...)");
        }
      }
      have_header = true;
      continue;
    }
    const auto fields = split(line);
    if (fields.size() < col.size()) {
      throw InputError(file,
                       line_no,
                       "expected " + std::to_string(col.size()) + " fields, found " +
                           std::to_string(fields.size()));
    }
    auto field = [&](const char* name) { return fields[static_cast<std::size_t>(col.at(name))]; };
    auto has = [&](const char* name) { return col.count(name) > 0; };
    TrackRow r;
    r.source_line = line_no;
    r.frame = parse_number<std::int64_t>(field("frame"), file, line_no, "frame");
    r.timestamp_ns =
        parse_number<std::int64_t>(field("timestamp_ns"), file, line_no, "timestamp_ns");
    r.track_id = parse_number<std::int64_t>(field("track_id"), file, line_no, "track_id");
    r.bearing = parse_number<double>(field("bearing_rad"), file, line_no, "bearing_rad");
    if (r.frame < 0) throw InputError(file, line_no, "negative frame index");
    if (r.track_id < 0) throw InputError(file, line_no, "negative track id");
    if (std::abs(r.bearing) > kPi + 1e-6) {
      throw InputError(file, line_no, "bearing_rad outside [-pi, pi]");
    }
    if (has("image_angle_rad")) {
      r.image_angle =
          parse_number<double>(field("image_angle_rad"), file, line_no, "image_angle_rad");
    }
    if (has("edge_pixels")) {
      r.edge_pixels = parse_number<int>(field("edge_pixels"), file, line_no, "edge_pixels");
    }
    if (has("r_inner"))
      r.r_inner = parse_number<double>(field("r_inner"), file, line_no, "r_inner");
    if (has("r_outer"))
      r.r_outer = parse_number<double>(field("r_outer"), file, line_no, "r_outer");
    if (has("matched_frame")) {
      r.matched_frame =
          parse_number<std::int64_t>(field("matched_frame"), file, line_no, "matched_frame");
      if (r.matched_frame >= r.frame) {
        throw InputError(file, line_no, "matched_frame must be earlier than frame (or -1)");
      }
    }
    if (has("distance"))
      r.distance = parse_number<double>(field("distance"), file, line_no, "distance");
    if (has("line")) r.line = parse_number<int>(field("line"), file, line_no, "line");
    if (has("matched_line")) {
      r.matched_line = parse_number<int>(field("matched_line"), file, line_no, "matched_line");
    }
    if (has("crowded")) {
      const int c = parse_number<int>(field("crowded"), file, line_no, "crowded");
      if (c != 0 && c != 1) throw InputError(file, line_no, "column 'crowded' must be 0 or 1");
      r.crowded = c == 1;
    }
    if (has("annulus_fraction")) {
      const double f =
          parse_number<double>(field("annulus_fraction"), file, line_no, "annulus_fraction");
      if (f > 1.5)
        throw InputError(file, line_no, "annulus_fraction above 1.5 (a fraction of R_max - R_min)");
      if (f >= 0) r.annulus_fraction = f;  // -1: not known
    }
    rows.push_back(r);
  }
  if (!have_header) throw InputError(file, 0, "empty file: no header line");
  rows.shrink_to_fit();  // a long run's rows are held through the calibration
  return rows;
}

}  // namespace omnivert
