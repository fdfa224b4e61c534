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

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert {
namespace {

namespace fs = std::filesystem;

// Writes `bytes` to `path` through a temporary file in the same directory and a rename.
void write_atomically(const fs::path& path, const std::string& bytes) {
  fs::path tmp = path;
  tmp += ".partial";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw InputError(path.string(), 0, "cannot open for writing");
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    f.flush();
    if (!f) {
      f.close();
      std::error_code ec;
      fs::remove(tmp, ec);
      throw InputError(path.string(), 0, "write failed (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(path.string(), 0, "cannot rename the finished file into place");
  }
}

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
    throw InputError(file, line, "column '" + column + "': '" + std::string(s) +
                                     "' is not a valid number");
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
    rows->push_back(r);
  }
}

void write_tracks_csv(const fs::path& path, const std::vector<TrackRow>& rows) {
  std::string out;
  out.reserve(rows.size() * 96 + 128);
  out +=
      "frame,timestamp_ns,track_id,bearing_rad,image_angle_rad,edge_pixels,r_inner,r_outer,"
      "matched_frame,distance\n";
  char buf[256];
  for (const TrackRow& r : rows) {
    const int n = std::snprintf(buf,
                                sizeof(buf),
                                "%lld,%lld,%lld,%.9f,%.9f,%d,%.3f,%.3f,%lld,%.6f\n",
                                static_cast<long long>(r.frame),
                                static_cast<long long>(r.timestamp_ns),
                                static_cast<long long>(r.track_id),
                                r.bearing,
                                r.image_angle,
                                r.edge_pixels,
                                r.r_inner,
                                r.r_outer,
                                static_cast<long long>(r.matched_frame),
                                r.distance);
    out.append(buf, static_cast<std::size_t>(n));
  }
  write_atomically(path, out);
}

std::vector<TrackRow> read_tracks_csv(const fs::path& path) {
  const std::string file = path.string();
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
      for (int i = 0; i < static_cast<int>(names.size()); ++i) col[std::string(names[i])] = i;
      for (const char* required : {"frame", "timestamp_ns", "track_id", "bearing_rad"}) {
        if (!col.count(required)) {
          throw InputError(file, line_no, std::string("header lacks the column '") + required +
                                              "' (expected frame,timestamp_ns,track_id,"
                                              "bearing_rad,...)");
        }
      }
      have_header = true;
      continue;
    }
    const auto fields = split(line);
    if (fields.size() < col.size()) {
      throw InputError(file, line_no, "expected " + std::to_string(col.size()) +
                                          " fields, found " + std::to_string(fields.size()));
    }
    auto field = [&](const char* name) { return fields[static_cast<std::size_t>(col.at(name))]; };
    auto has = [&](const char* name) { return col.count(name) > 0; };
    TrackRow r;
    r.frame = parse_number<std::int64_t>(field("frame"), file, line_no, "frame");
    r.timestamp_ns = parse_number<std::int64_t>(field("timestamp_ns"), file, line_no, "timestamp_ns");
    r.track_id = parse_number<std::int64_t>(field("track_id"), file, line_no, "track_id");
    r.bearing = parse_number<double>(field("bearing_rad"), file, line_no, "bearing_rad");
    if (r.frame < 0) throw InputError(file, line_no, "negative frame index");
    if (r.track_id < 0) throw InputError(file, line_no, "negative track id");
    if (std::abs(r.bearing) > kPi + 1e-6) {
      throw InputError(file, line_no, "bearing_rad outside [-pi, pi]");
    }
    if (has("image_angle_rad")) {
      r.image_angle = parse_number<double>(field("image_angle_rad"), file, line_no, "image_angle_rad");
    }
    if (has("edge_pixels")) {
      r.edge_pixels = parse_number<int>(field("edge_pixels"), file, line_no, "edge_pixels");
    }
    if (has("r_inner")) r.r_inner = parse_number<double>(field("r_inner"), file, line_no, "r_inner");
    if (has("r_outer")) r.r_outer = parse_number<double>(field("r_outer"), file, line_no, "r_outer");
    if (has("matched_frame")) {
      r.matched_frame =
          parse_number<std::int64_t>(field("matched_frame"), file, line_no, "matched_frame");
      if (r.matched_frame >= r.frame) {
        throw InputError(file, line_no, "matched_frame must be earlier than frame (or -1)");
      }
    }
    if (has("distance")) r.distance = parse_number<double>(field("distance"), file, line_no, "distance");
    rows.push_back(r);
  }
  if (!have_header) throw InputError(file, 0, "empty file: no header line");
  return rows;
}

namespace {

// A step of 1, 2 or 5 x 10^k giving about `target` ticks over `span`.
double nice_step(double span, int target) {
  const double raw = span / std::max(1, target);
  const double p = std::pow(10.0, std::floor(std::log10(std::max(raw, 1e-9))));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= raw) return std::max(1.0, m * p);
  }
  return std::max(1.0, 10.0 * p);
}

cv::Scalar track_colour(std::int64_t id) {
  // Golden-ratio hue walk: neighbouring ids get distinct hues; darkish for a white page.
  const double h = std::fmod(static_cast<double>(id) * 0.61803398875, 1.0) * 180.0;
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(h, 230, 190 - static_cast<double>((id % 3) * 30)));
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return cv::Scalar(c[0], c[1], c[2]);
}

}  // namespace

cv::Mat draw_tracks(const std::vector<TrackRow>& rows, const TrackPlotOptions& options) {
  const int W = std::max(400, options.width), H = std::max(300, options.height);
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 80, right = 30, top = 50, bottom = 60;
  const cv::Rect area(left, top, W - left - right, H - top - bottom);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const cv::Scalar black(0, 0, 0), grid(225, 225, 225);

  std::int64_t max_frame = 0;
  for (const TrackRow& r : rows) max_frame = std::max(max_frame, r.frame);
  const double x_max = std::max<double>(1.0, static_cast<double>(max_frame));
  auto px = [&](double frame) { return area.x + frame / x_max * area.width; };
  auto py = [&](double bearing) {  // +180 at the top
    return area.y + (kPi - bearing) / kTwoPi * area.height;
  };
  auto pt = [](double x, double y) {
    return cv::Point(static_cast<int>(std::lround(x * 16)), static_cast<int>(std::lround(y * 16)));
  };

  // Grid, ticks and labels.
  for (int deg = -180; deg <= 180; deg += 45) {
    const int y = static_cast<int>(std::lround(py(deg2rad(deg))));
    cv::line(img, {area.x, y}, {area.x + area.width, y}, grid, 1);
    cv::line(img, {area.x - 6, y}, {area.x, y}, black, 1);
    const std::string s = std::to_string(deg);
    int base = 0;
    const cv::Size ts = cv::getTextSize(s, font, 0.45, 1, &base);
    cv::putText(img, s, {area.x - 10 - ts.width, y + ts.height / 2}, font, 0.45, black, 1, cv::LINE_AA);
  }
  const double step = nice_step(x_max, 10);
  for (double f = 0; f <= x_max + 1e-9; f += step) {
    const int x = static_cast<int>(std::lround(px(f)));
    cv::line(img, {x, area.y}, {x, area.y + area.height}, grid, 1);
    cv::line(img, {x, area.y + area.height}, {x, area.y + area.height + 6}, black, 1);
    const std::string s = std::to_string(static_cast<long long>(f));
    int base = 0;
    const cv::Size ts = cv::getTextSize(s, font, 0.45, 1, &base);
    cv::putText(img, s, {x - ts.width / 2, area.y + area.height + 22}, font, 0.45, black, 1,
                cv::LINE_AA);
  }
  cv::rectangle(img, area, black, 1);
  {
    const std::string s = "frame";
    int base = 0;
    const cv::Size ts = cv::getTextSize(s, font, 0.55, 1, &base);
    cv::putText(img, s, {area.x + area.width / 2 - ts.width / 2, H - 12}, font, 0.55, black, 1,
                cv::LINE_AA);
  }
  {
    // Vertical y label: draw horizontally, rotate, paste.
    const std::string s = "bearing [deg]";
    int base = 0;
    const cv::Size ts = cv::getTextSize(s, font, 0.55, 1, &base);
    cv::Mat label(ts.height + base + 4, ts.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(label, s, {2, ts.height + 1}, font, 0.55, black, 1, cv::LINE_AA);
    cv::Mat rotated;
    cv::rotate(label, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int y0 = std::max(0, area.y + area.height / 2 - rotated.rows / 2);
    if (y0 + rotated.rows <= H && rotated.cols + 8 <= left) {
      rotated.copyTo(img(cv::Rect(8, y0, rotated.cols, rotated.rows)));
    }
  }
  {
    std::ostringstream t;
    std::map<std::int64_t, int> n;
    for (const TrackRow& r : rows) ++n[r.track_id];
    t << options.title << "  (" << rows.size() << " detections, " << n.size() << " tracks)";
    cv::putText(img, t.str(), {area.x, 32}, font, 0.6, black, 1, cv::LINE_AA);
  }

  // Tracks: rows grouped by id, in frame order.
  std::map<std::int64_t, std::vector<const TrackRow*>> tracks;
  for (const TrackRow& r : rows) tracks[r.track_id].push_back(&r);
  cv::Mat plot = img(area);  // drawing into the sub-image clips at the axes
  const double ox = -area.x, oy = -area.y;
  for (auto& [id, dets] : tracks) {
    std::stable_sort(dets.begin(), dets.end(), [](const TrackRow* a, const TrackRow* b) {
      return a->frame < b->frame;
    });
    const cv::Scalar c = track_colour(id);
    for (std::size_t k = 1; k < dets.size(); ++k) {
      // Predecessor: the detection it was matched to when known, else the previous one.
      const TrackRow* b = dets[k];
      const TrackRow* a = dets[k - 1];
      if (b->matched_frame >= 0) {
        for (std::size_t m = k; m-- > 0;) {
          if (dets[m]->frame == b->matched_frame) {
            a = dets[m];
            break;
          }
        }
      }
      if (a->frame == b->frame) continue;
      const double d = angle_diff(b->bearing, a->bearing);  // the short way round
      const double xa = px(static_cast<double>(a->frame)) + ox;
      const double xb = px(static_cast<double>(b->frame)) + ox;
      // Unwrapped: from a to a + d and from b - d to b; when the track crosses +-180 degrees
      // each piece leaves the plot at its border (clipped), so no line spans the plot.
      cv::line(plot, pt(xa, py(a->bearing) + oy), pt(xb, py(a->bearing + d) + oy), c, 1,
               cv::LINE_AA, 4);
      if (std::abs(a->bearing + d) > kPi) {
        cv::line(plot, pt(xa, py(b->bearing - d) + oy), pt(xb, py(b->bearing) + oy), c, 1,
                 cv::LINE_AA, 4);
      }
    }
    for (const TrackRow* r : dets) {
      cv::circle(plot, pt(px(static_cast<double>(r->frame)) + ox, py(r->bearing) + oy), 2 * 16, c,
                 1, cv::LINE_AA, 4);
    }
    if (options.draw_ids && !dets.empty()) {
      const TrackRow* s = dets.front();
      cv::putText(plot, std::to_string(id),
                  cv::Point(static_cast<int>(px(static_cast<double>(s->frame)) + ox) + 3,
                            static_cast<int>(py(s->bearing) + oy) - 4),
                  font, 0.38, c, 1, cv::LINE_AA);
    }
  }
  return img;
}

void write_tracks_png(const fs::path& path,
                      const std::vector<TrackRow>& rows,
                      const TrackPlotOptions& options) {
  const cv::Mat img = draw_tracks(rows, options);
  std::vector<uchar> buf;
  if (!cv::imencode(".png", img, buf)) throw InputError(path.string(), 0, "PNG encoding failed");
  write_atomically(path, std::string(buf.begin(), buf.end()));
}

}  // namespace omnivert
