#include "omnivert/viz/tracks_plot.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "omnivert/image/image_io.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert {

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
    cv::putText(
        img, s, {area.x - 10 - ts.width, y + ts.height / 2}, font, 0.45, black, 1, cv::LINE_AA);
  }
  const double step = nice_step(x_max, 10);
  for (double f = 0; f <= x_max + 1e-9; f += step) {
    const int x = static_cast<int>(std::lround(px(f)));
    cv::line(img, {x, area.y}, {x, area.y + area.height}, grid, 1);
    cv::line(img, {x, area.y + area.height}, {x, area.y + area.height + 6}, black, 1);
    const std::string s = std::to_string(static_cast<long long>(f));
    int base = 0;
    const cv::Size ts = cv::getTextSize(s, font, 0.45, 1, &base);
    cv::putText(
        img, s, {x - ts.width / 2, area.y + area.height + 22}, font, 0.45, black, 1, cv::LINE_AA);
  }
  cv::rectangle(img, area, black, 1);
  {
    const std::string s = "frame";
    int base = 0;
    const cv::Size ts = cv::getTextSize(s, font, 0.55, 1, &base);
    cv::putText(img,
                s,
                {area.x + area.width / 2 - ts.width / 2, H - 12},
                font,
                0.55,
                black,
                1,
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
      // Predecessor (as in evaluate_tracking): among the track's detections in the frame it
      // was matched to (else its latest earlier frame), the nearest in bearing.
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
      if (pred_frame < 0) continue;
      const TrackRow* a = nullptr;
      for (std::size_t m = k; m-- > 0;) {
        if (dets[m]->frame != pred_frame) continue;
        if (!a || std::abs(angle_diff(dets[m]->bearing, b->bearing)) <
                      std::abs(angle_diff(a->bearing, b->bearing))) {
          a = dets[m];
        }
      }
      const double d = angle_diff(b->bearing, a->bearing);  // the short way round
      const double xa = px(static_cast<double>(a->frame)) + ox;
      const double xb = px(static_cast<double>(b->frame)) + ox;
      // Unwrapped: from a to a + d and from b - d to b; when the track crosses +-180 degrees
      // each piece leaves the plot at its border (clipped), so no line spans the plot.
      cv::line(
          plot, pt(xa, py(a->bearing) + oy), pt(xb, py(a->bearing + d) + oy), c, 1, cv::LINE_AA, 4);
      if (std::abs(a->bearing + d) > kPi) {
        cv::line(plot,
                 pt(xa, py(b->bearing - d) + oy),
                 pt(xb, py(b->bearing) + oy),
                 c,
                 1,
                 cv::LINE_AA,
                 4);
      }
    }
    for (const TrackRow* r : dets) {
      cv::circle(plot,
                 pt(px(static_cast<double>(r->frame)) + ox, py(r->bearing) + oy),
                 2 * 16,
                 c,
                 1,
                 cv::LINE_AA,
                 4);
    }
    if (options.draw_ids && !dets.empty()) {
      const TrackRow* s = dets.front();
      cv::putText(plot,
                  std::to_string(id),
                  cv::Point(static_cast<int>(px(static_cast<double>(s->frame)) + ox) + 3,
                            static_cast<int>(py(s->bearing) + oy) - 4),
                  font,
                  0.38,
                  c,
                  1,
                  cv::LINE_AA);
    }
  }
  return img;
}

void write_tracks_png(const fs::path& path,
                      const std::vector<TrackRow>& rows,
                      const TrackPlotOptions& options) {
  write_image_atomic(path.string(), draw_tracks(rows, options));
}

}  // namespace omnivert
