#include "omnivert/viz/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <opencv2/imgproc.hpp>

namespace omnivert::viz {

namespace {

const cv::Scalar kBlack(0, 0, 0), kGrey(160, 160, 160), kLight(225, 225, 225),
    kWhite(255, 255, 255);

void text(cv::Mat& img,
          const std::string& s,
          cv::Point p,
          double scale = 0.5,
          cv::Scalar c = kBlack,
          bool center = false) {
  int base = 0;
  const cv::Size sz = cv::getTextSize(s, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &base);
  if (center) p.x -= sz.width / 2;
  cv::putText(img, s, p, cv::FONT_HERSHEY_SIMPLEX, scale, c, 1, cv::LINE_AA);
}

void vertical_text(cv::Mat& img, const std::string& s, cv::Point center, double scale = 0.5) {
  int base = 0;
  const cv::Size sz = cv::getTextSize(s, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &base);
  cv::Mat t(sz.height + base + 4, sz.width + 4, CV_8UC3, kWhite);
  cv::putText(t, s, {2, sz.height + 2}, cv::FONT_HERSHEY_SIMPLEX, scale, kBlack, 1, cv::LINE_AA);
  cv::Mat r;
  cv::rotate(t, r, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int x = std::clamp(center.x - r.cols / 2, 0, img.cols - r.cols);
  const int y = std::clamp(center.y - r.rows / 2, 0, img.rows - r.rows);
  r.copyTo(img(cv::Rect(x, y, r.cols, r.rows)));
}

std::string fmt(double v) {
  char b[32];
  if (std::abs(v) < 1e-12) v = 0.0;
  if (v != 0 && (std::abs(v) < 0.01 || std::abs(v) >= 1e5)) {
    std::snprintf(b, sizeof b, "%.1e", v);
  } else {
    std::snprintf(b, sizeof b, "%g", std::round(v * 1000) / 1000);
  }
  return b;
}

// "Nice" tick step for a range, about n ticks.
double tick_step(double range, int n) {
  const double raw = range / n;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * mag >= raw) return m * mag;
  return 10 * mag;
}

void dashed_line(cv::Mat& img, cv::Point a, cv::Point b, cv::Scalar c, int thickness = 1) {
  const double len = std::hypot(b.x - a.x, b.y - a.y);
  const int n = std::max(1, static_cast<int>(len / 6));
  for (int i = 0; i < n; i += 2) {
    const double t0 = static_cast<double>(i) / n,
                 t1 = std::min(1.0, static_cast<double>(i + 1) / n);
    cv::line(img,
             {static_cast<int>(a.x + t0 * (b.x - a.x)), static_cast<int>(a.y + t0 * (b.y - a.y))},
             {static_cast<int>(a.x + t1 * (b.x - a.x)), static_cast<int>(a.y + t1 * (b.y - a.y))},
             c,
             thickness,
             cv::LINE_AA);
  }
}

}  // namespace

cv::Scalar plot_color(int i) {
  static const cv::Scalar k[] = {{180, 119, 31},
                                 {14, 127, 255},
                                 {44, 160, 44},
                                 {40, 39, 214},
                                 {189, 103, 148},
                                 {75, 86, 140},
                                 {194, 119, 227},
                                 {127, 127, 127}};
  return k[static_cast<std::size_t>(i) % 8];
}

cv::Mat draw_heatmap(const cv::Mat1f& m, const HeatmapOptions& o) {
  CV_Assert(!m.empty());
  double lo = o.lo, hi = o.hi;
  if (!(lo < hi)) {
    std::vector<float> v(m.begin(), m.end());
    std::sort(v.begin(), v.end());
    lo = v[static_cast<std::size_t>(0.01 * (v.size() - 1))];
    hi = v[static_cast<std::size_t>(0.99 * (v.size() - 1))];
    if (!(lo < hi)) hi = lo + 1.0;
  }
  const int cell = std::max(1, o.cell);
  const int mw = m.cols * cell, mh = m.rows * cell;
  const int left = 70, top = 40, bottom = 55, bar_gap = 25, bar_w = 22, right = 90;
  cv::Mat img(top + mh + bottom, left + mw + bar_gap + bar_w + right, CV_8UC3, kWhite);
  cv::Mat1b u8(m.rows, m.cols);
  for (int i = 0; i < m.rows; ++i)
    for (int j = 0; j < m.cols; ++j)
      u8(i, j) = cv::saturate_cast<uchar>(255.0 * (m(i, j) - lo) / (hi - lo));
  cv::Mat col, big;
  cv::applyColorMap(u8, col, cv::COLORMAP_INFERNO);
  cv::resize(col, big, {mw, mh}, 0, 0, cv::INTER_NEAREST);
  big.copyTo(img(cv::Rect(left, top, mw, mh)));
  cv::rectangle(img, cv::Rect(left - 1, top - 1, mw + 2, mh + 2), kBlack);
  // Axis ticks.
  const double step = tick_step(o.axis_max, 6);
  for (double v = 0; v <= o.axis_max + 1e-9; v += step) {
    const int px = left + static_cast<int>(v / o.axis_max * (mw - 1));
    const int py = top + static_cast<int>(v / o.axis_max * (mh - 1));
    cv::line(img, {px, top + mh}, {px, top + mh + 5}, kBlack);
    text(img, fmt(v), {px, top + mh + 20}, 0.45, kBlack, true);
    cv::line(img, {left - 5, py}, {left, py}, kBlack);
    text(img, fmt(v), {left - 45, py + 5}, 0.45);
  }
  text(img, o.axis_label, {left + mw / 2, top + mh + 45}, 0.5, kBlack, true);
  vertical_text(img, o.axis_label, {15, top + mh / 2});
  text(img, o.title, {left + mw / 2, 25}, 0.6, kBlack, true);
  // Colour bar.
  const int bx = left + mw + bar_gap;
  for (int y = 0; y < mh; ++y) {
    cv::Mat1b v(1, 1, cv::saturate_cast<uchar>(255.0 * (mh - 1 - y) / (mh - 1)));
    cv::Mat c;
    cv::applyColorMap(v, c, cv::COLORMAP_INFERNO);
    cv::line(img, {bx, top + y}, {bx + bar_w, top + y}, c.at<cv::Vec3b>(0, 0));
  }
  cv::rectangle(img, cv::Rect(bx - 1, top - 1, bar_w + 2, mh + 2), kBlack);
  for (int k = 0; k <= 4; ++k) {
    const double v = lo + (hi - lo) * k / 4.0;
    const int y = top + mh - 1 - static_cast<int>(k / 4.0 * (mh - 1));
    cv::line(img, {bx + bar_w, y}, {bx + bar_w + 4, y}, kBlack);
    text(img, fmt(v), {bx + bar_w + 7, y + 5}, 0.42);
  }
  text(img, o.scale_label, {bx + bar_w / 2, top + mh + 20}, 0.42, kBlack, true);
  return img;
}

namespace {

// The plot area in the image (margins left, top; size pw x ph) and the data ranges it shows.
struct PlotFrame {
  static constexpr int left = 80, right = 30, top = 45, bottom = 65;
  int pw = 0, ph = 0;
  double xlo = 0, xhi = 0, ylo = 0, yhi = 0;
  int X(double x) const {
    return left + static_cast<int>(std::lround((x - xlo) / (xhi - xlo) * pw));
  }
  int Y(double y) const {
    return top + ph - static_cast<int>(std::lround((y - ylo) / (yhi - ylo) * ph));
  }
};

// The axis ranges: the options', else the data's (with a margin in y). With a logarithmic
// y axis, series holds log10(y) and the y range is converted too.
PlotFrame plot_frame(const std::vector<PlotSeries>& series, const PlotOptions& o) {
  PlotFrame f;
  double xlo = o.x_lo, xhi = o.x_hi, ylo = o.y_lo, yhi = o.y_hi;
  if (o.log_y && ylo < yhi) {
    ylo = ylo > 0 ? std::log10(ylo) : 0.0;
    yhi = std::log10(yhi);
  }
  if (!(xlo < xhi) || !(ylo < yhi)) {
    double a = std::numeric_limits<double>::infinity(), b = -a, c = a, d = -a;
    for (const auto& s : series)
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        a = std::min(a, s.x[i]), b = std::max(b, s.x[i]), c = std::min(c, s.y[i]),
        d = std::max(d, s.y[i]);
      }
    if (!std::isfinite(a)) a = 0, b = 1, c = 0, d = 1;
    if (!(xlo < xhi)) {
      xlo = a, xhi = b > a ? b : a + 1;
    }
    if (!(ylo < yhi)) {
      const double pad = d > c ? 0.08 * (d - c) : 0.5;
      ylo = c - pad, yhi = d + pad;
    }
  }
  f.xlo = xlo, f.xhi = xhi, f.ylo = ylo, f.yhi = yhi;
  f.pw = o.width - PlotFrame::left - PlotFrame::right;
  f.ph = o.height - PlotFrame::top - PlotFrame::bottom;
  return f;
}

// Grid lines, ticks and tick labels of both axes, the frame, and the options' vertical lines.
void draw_plot_axes(cv::Mat& img, const PlotFrame& f, const PlotOptions& o) {
  const int left = PlotFrame::left, top = PlotFrame::top, pw = f.pw, ph = f.ph;
  const double xlo = f.xlo, xhi = f.xhi, ylo = f.ylo, yhi = f.yhi;
  const double xs = tick_step(xhi - xlo, 8), ys = tick_step(yhi - ylo, 6);
  for (double v = std::ceil(xlo / xs - 1e-9) * xs; v <= xhi + 1e-9 * xs; v += xs) {
    cv::line(img, {f.X(v), top}, {f.X(v), top + ph}, kLight);
    cv::line(img, {f.X(v), top + ph}, {f.X(v), top + ph + 5}, kBlack);
    text(img, fmt(v), {f.X(v), top + ph + 20}, 0.45, kBlack, true);
  }
  if (o.log_y) {
    // Decades labelled, 2 and 5 times each decade as light lines.
    for (double d = std::floor(ylo); d <= yhi + 1e-9; d += 1.0) {
      for (double m : {1.0, 2.0, 5.0}) {
        const double v = d + std::log10(m);
        if (v < ylo - 1e-9 || v > yhi + 1e-9) continue;
        cv::line(img, {left, f.Y(v)}, {left + pw, f.Y(v)}, kLight);
        cv::line(img, {left - (m == 1.0 ? 5 : 3), f.Y(v)}, {left, f.Y(v)}, kBlack);
        if (m == 1.0 || yhi - ylo < 2.5)
          text(img, fmt(std::pow(10.0, v)), {left - 55, f.Y(v) + 5}, 0.45);
      }
    }
  } else {
    for (double v = std::ceil(ylo / ys - 1e-9) * ys; v <= yhi + 1e-9 * ys; v += ys) {
      cv::line(img, {left, f.Y(v)}, {left + pw, f.Y(v)}, kLight);
      cv::line(img, {left - 5, f.Y(v)}, {left, f.Y(v)}, kBlack);
      text(img, fmt(v), {left - 55, f.Y(v) + 5}, 0.45);
    }
  }
  cv::rectangle(img, cv::Rect(left, top, pw, ph), kBlack);
  for (std::size_t k = 0; k < o.vertical_lines.size(); ++k) {
    const double v = o.vertical_lines[k];
    if (v < xlo || v > xhi) continue;
    dashed_line(img, {f.X(v), top}, {f.X(v), top + ph}, kGrey, 2);
    if (k < o.vertical_labels.size())
      text(img, o.vertical_labels[k], {f.X(v) + 4, top + ph - 8}, 0.45, {90, 90, 90});
  }
}

// The series, clipped to the plot area; returns where the data is drawn (for the legend).
cv::Mat1b draw_series(cv::Mat& img, const PlotFrame& f, const std::vector<PlotSeries>& series) {
  const int left = PlotFrame::left, top = PlotFrame::top;
  cv::Mat plot_area = img(cv::Rect(left, top, f.pw + 1, f.ph + 1));
  cv::Mat1b ink(f.ph + 1, f.pw + 1, uchar{0});
  for (std::size_t si = 0; si < series.size(); ++si) {
    const auto& s = series[si];
    std::vector<cv::Point> pts;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i]))
        pts.push_back({f.X(s.x[i]) - left, f.Y(s.y[i]) - top});
    for (std::size_t i = 1; i < pts.size(); ++i) {
      if (s.dashed) {
        dashed_line(plot_area, pts[i - 1], pts[i], s.color, 2);
      } else {
        cv::line(plot_area, pts[i - 1], pts[i], s.color, 2, cv::LINE_AA);
      }
    }
    for (std::size_t i = 1; i < pts.size(); ++i) cv::line(ink, pts[i - 1], pts[i], 255, 3);
    for (const auto& p : pts) cv::circle(ink, p, 5, 255, cv::FILLED);
    if (s.markers)
      for (const auto& p : pts) cv::circle(plot_area, p, 4, s.color, cv::FILLED, cv::LINE_AA);
  }
  return ink;
}

// Legend, inside the plot (series without a name are left out of it), in the corner (or
// side) where it covers the least data (`ink`); the preferred one on ties.
void draw_legend(cv::Mat& img,
                 const PlotFrame& f,
                 const std::vector<PlotSeries>& series,
                 const cv::Mat1b& ink,
                 bool legend_bottom) {
  std::vector<const PlotSeries*> named;
  for (const auto& s : series)
    if (!s.name.empty()) named.push_back(&s);
  int lw = 0;
  for (const PlotSeries* sp : named) {
    const PlotSeries& s = *sp;
    int base = 0;
    lw = std::max(lw, cv::getTextSize(s.name, cv::FONT_HERSHEY_SIMPLEX, 0.45, 1, &base).width);
  }
  if (named.empty()) return;
  const int pw = f.pw, ph = f.ph;
  const int bw = lw + 50, bh = 20 * static_cast<int>(named.size()) + 8;
  const int xr = pw - bw - 8, xl = 8, yt = 8, yb = ph - bh - 24, ym = (ph - bh) / 2;
  std::vector<cv::Point> spots = {{xr, yt}, {xr, yb}, {xl, yt}, {xl, yb}, {xr, ym}, {xl, ym}};
  if (legend_bottom) std::swap(spots[0], spots[1]);
  cv::Point best = spots[0];
  int best_ink = std::numeric_limits<int>::max();
  for (const auto& sp : spots) {
    const cv::Rect r = cv::Rect(sp.x, sp.y, bw, bh) & cv::Rect(0, 0, ink.cols, ink.rows);
    const int n = r.area() > 0 ? cv::countNonZero(ink(r)) : 0;
    if (n < best_ink) best_ink = n, best = sp;
  }
  const cv::Rect box(PlotFrame::left + best.x, PlotFrame::top + best.y, bw, bh);
  img(box).setTo(kWhite);
  cv::rectangle(img, box, kGrey);
  for (std::size_t si = 0; si < named.size(); ++si) {
    const PlotSeries& ns = *named[si];
    const int y = box.y + 16 + 20 * static_cast<int>(si);
    if (ns.dashed) {
      dashed_line(img, {box.x + 6, y - 4}, {box.x + 36, y - 4}, ns.color, 2);
    } else {
      cv::line(img, {box.x + 6, y - 4}, {box.x + 36, y - 4}, ns.color, 2, cv::LINE_AA);
    }
    text(img, ns.name, {box.x + 42, y}, 0.45);
  }
}

}  // namespace

cv::Mat draw_plot(const std::vector<PlotSeries>& series_in, const PlotOptions& o) {
  // A logarithmic y axis plots log10(y) (non-positive values are left out) and labels the
  // ticks with the values themselves.
  std::vector<PlotSeries> logged;
  if (o.log_y) {
    logged = series_in;
    for (auto& s : logged)
      for (double& v : s.y) v = v > 0 ? std::log10(v) : std::numeric_limits<double>::quiet_NaN();
  }
  const std::vector<PlotSeries>& series = o.log_y ? logged : series_in;
  const PlotFrame f = plot_frame(series, o);
  cv::Mat img(o.height, o.width, CV_8UC3, kWhite);
  draw_plot_axes(img, f, o);
  const cv::Mat1b ink = draw_series(img, f, series);
  text(img, o.title, {o.width / 2, 28}, 0.6, kBlack, true);
  text(img, o.x_label, {PlotFrame::left + f.pw / 2, o.height - 18}, 0.5, kBlack, true);
  vertical_text(img, o.y_label, {15, PlotFrame::top + f.ph / 2});
  draw_legend(img, f, series, ink, o.legend_bottom);
  return img;
}

}  // namespace omnivert::viz
