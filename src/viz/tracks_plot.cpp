#include "omnivert/viz/tracks_plot.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/image/image_io.hpp"

namespace omnivert::viz {

namespace fs = std::filesystem;

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

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
const cv::Scalar kBlack(0, 0, 0), kGrid(225, 225, 225);

// The plot's axes: frame index to x, bearing to y (+180 degrees at the top), in pixels.
struct Axes {
  cv::Rect area;
  double x_max = 1.0;
  double px(double frame) const { return area.x + frame / x_max * area.width; }
  double py(double bearing) const { return area.y + (kPi - bearing) / kTwoPi * area.height; }
};

// A point in 1/16 pixel (4 fractional bits).
cv::Point pt(double x, double y) {
  return cv::Point(static_cast<int>(std::lround(x * 16)), static_cast<int>(std::lround(y * 16)));
}

// Grid, ticks and tick labels, and the frame.
void draw_grid(cv::Mat& img, const Axes& ax) {
  const cv::Rect& area = ax.area;
  for (int deg = -180; deg <= 180; deg += 45) {
    const int y = static_cast<int>(std::lround(ax.py(deg2rad(deg))));
    cv::line(img, {area.x, y}, {area.x + area.width, y}, kGrid, 1);
    cv::line(img, {area.x - 6, y}, {area.x, y}, kBlack, 1);
    const std::string s = std::to_string(deg);
    int base = 0;
    const cv::Size ts = cv::getTextSize(s, kFont, 0.45, 1, &base);
    cv::putText(
        img, s, {area.x - 10 - ts.width, y + ts.height / 2}, kFont, 0.45, kBlack, 1, cv::LINE_AA);
  }
  const double step = nice_step(ax.x_max, 10);
  for (double f = 0; f <= ax.x_max + 1e-9; f += step) {
    const int x = static_cast<int>(std::lround(ax.px(f)));
    cv::line(img, {x, area.y}, {x, area.y + area.height}, kGrid, 1);
    cv::line(img, {x, area.y + area.height}, {x, area.y + area.height + 6}, kBlack, 1);
    const std::string s = std::to_string(static_cast<long long>(f));
    int base = 0;
    const cv::Size ts = cv::getTextSize(s, kFont, 0.45, 1, &base);
    cv::putText(
        img, s, {x - ts.width / 2, area.y + area.height + 22}, kFont, 0.45, kBlack, 1, cv::LINE_AA);
  }
  cv::rectangle(img, area, kBlack, 1);
}

// Axis labels ("frame" below, "bearing [deg]" rotated on the left) and the title.
void draw_labels(cv::Mat& img,
                 const Axes& ax,
                 int left,
                 const std::vector<TrackRow>& rows,
                 const std::string& title) {
  const cv::Rect& area = ax.area;
  {
    const std::string s = "frame";
    int base = 0;
    const cv::Size ts = cv::getTextSize(s, kFont, 0.55, 1, &base);
    cv::putText(img,
                s,
                {area.x + area.width / 2 - ts.width / 2, img.rows - 12},
                kFont,
                0.55,
                kBlack,
                1,
                cv::LINE_AA);
  }
  {
    // Vertical y label: draw horizontally, rotate, paste.
    const std::string s = "bearing [deg]";
    int base = 0;
    const cv::Size ts = cv::getTextSize(s, kFont, 0.55, 1, &base);
    cv::Mat label(ts.height + base + 4, ts.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(label, s, {2, ts.height + 1}, kFont, 0.55, kBlack, 1, cv::LINE_AA);
    cv::Mat rotated;
    cv::rotate(label, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int y0 = std::max(0, area.y + area.height / 2 - rotated.rows / 2);
    if (y0 + rotated.rows <= img.rows && rotated.cols + 8 <= left) {
      rotated.copyTo(img(cv::Rect(8, y0, rotated.cols, rotated.rows)));
    }
  }
  std::ostringstream t;
  std::map<std::int64_t, int> n;
  for (const TrackRow& r : rows) ++n[r.track_id];
  t << title << "  (" << rows.size() << " detections, " << n.size() << " tracks)";
  cv::putText(img, t.str(), {area.x, 32}, kFont, 0.6, kBlack, 1, cv::LINE_AA);
}

// The predecessor of dets[k] (as in evaluate_tracking): among the track's detections in the
// frame it was matched to (else its latest earlier frame), the nearest in bearing; null when
// there is none.
const TrackRow* predecessor(const std::vector<const TrackRow*>& dets, std::size_t k) {
  const TrackRow* b = dets[k];
  std::int64_t pred_frame = -1;
  for (std::size_t m = k; m-- > 0;) {
    if (dets[m]->frame == b->matched_frame) pred_frame = b->matched_frame;
  }
  if (pred_frame < 0) {
    for (std::size_t m = k; m-- > 0;) {
      if (dets[m]->frame < b->frame) {
        pred_frame = dets[m]->frame;
        break;
      }
    }
  }
  if (pred_frame < 0) return nullptr;
  const TrackRow* a = nullptr;
  for (std::size_t m = k; m-- > 0;) {
    if (dets[m]->frame != pred_frame) continue;
    if (!a || std::abs(angle_diff(dets[m]->bearing, b->bearing)) <
                  std::abs(angle_diff(a->bearing, b->bearing))) {
      a = dets[m];
    }
  }
  return a;
}

// One track (dets sorted here in frame order) into the plot area `plot`: its links, its
// detections and optionally its id.
void draw_track(cv::Mat& plot,
                const Axes& ax,
                std::int64_t id,
                std::vector<const TrackRow*>& dets,
                bool draw_id) {
  const double ox = -ax.area.x, oy = -ax.area.y;
  std::stable_sort(dets.begin(), dets.end(), [](const TrackRow* a, const TrackRow* b) {
    return a->frame < b->frame;
  });
  const cv::Scalar c = track_colour(id);
  for (std::size_t k = 1; k < dets.size(); ++k) {
    const TrackRow* b = dets[k];
    const TrackRow* a = predecessor(dets, k);
    if (!a) continue;
    const double d = angle_diff(b->bearing, a->bearing);  // the short way round
    const double xa = ax.px(static_cast<double>(a->frame)) + ox;
    const double xb = ax.px(static_cast<double>(b->frame)) + ox;
    // Unwrapped: from a to a + d and from b - d to b; when the track crosses +-180 degrees
    // each piece leaves the plot at its border (clipped), so no line spans the plot.
    cv::line(plot,
             pt(xa, ax.py(a->bearing) + oy),
             pt(xb, ax.py(a->bearing + d) + oy),
             c,
             1,
             cv::LINE_AA,
             4);
    if (std::abs(a->bearing + d) > kPi) {
      cv::line(plot,
               pt(xa, ax.py(b->bearing - d) + oy),
               pt(xb, ax.py(b->bearing) + oy),
               c,
               1,
               cv::LINE_AA,
               4);
    }
  }
  for (const TrackRow* r : dets) {
    cv::circle(plot,
               pt(ax.px(static_cast<double>(r->frame)) + ox, ax.py(r->bearing) + oy),
               2 * 16,
               c,
               1,
               cv::LINE_AA,
               4);
  }
  if (draw_id && !dets.empty()) {
    const TrackRow* s = dets.front();
    cv::putText(plot,
                std::to_string(id),
                cv::Point(static_cast<int>(ax.px(static_cast<double>(s->frame)) + ox) + 3,
                          static_cast<int>(ax.py(s->bearing) + oy) - 4),
                kFont,
                0.38,
                c,
                1,
                cv::LINE_AA);
  }
}

}  // namespace

cv::Mat draw_tracks(const std::vector<TrackRow>& rows, const TrackPlotOptions& options) {
  const int W = std::max(400, options.width), H = std::max(300, options.height);
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 80, right = 30, top = 50, bottom = 60;
  std::int64_t max_frame = 0;
  for (const TrackRow& r : rows) max_frame = std::max(max_frame, r.frame);
  Axes ax;
  ax.area = cv::Rect(left, top, W - left - right, H - top - bottom);
  ax.x_max = std::max<double>(1.0, static_cast<double>(max_frame));
  draw_grid(img, ax);
  draw_labels(img, ax, left, rows, options.title);

  // Tracks: rows grouped by id, in frame order.
  std::map<std::int64_t, std::vector<const TrackRow*>> tracks;
  for (const TrackRow& r : rows) tracks[r.track_id].push_back(&r);
  cv::Mat plot = img(ax.area);  // drawing into the sub-image clips at the axes
  for (auto& [id, dets] : tracks) draw_track(plot, ax, id, dets, options.draw_ids);
  return img;
}

void write_tracks_png(const fs::path& path,
                      const std::vector<TrackRow>& rows,
                      const TrackPlotOptions& options) {
  write_image_atomic(path.string(), draw_tracks(rows, options));
}

}  // namespace omnivert::viz
