#include "omnivert/viz/convergence_plot.hpp"

#include <limits>

#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/viz/plot.hpp"

namespace omnivert::viz {

cv::Mat draw_convergence(const std::vector<calib::FrameEstimate>& history,
                         const std::optional<calib::Extrinsics>& truth,
                         const std::optional<calib::Extrinsics>& refined) {
  // Units shown: degrees for the angles, millimetres for rho.
  const double scale[3] = {rad2deg(1.0), 1000.0, rad2deg(1.0)};
  const char* names[3] = {"phi [deg]", "rho [mm]", "psi [deg]"};
  const char* sig_names[3] = {"sigma_phi [deg]", "sigma_rho [mm]", "sigma_psi [deg]"};
  std::vector<cv::Mat> top, bottom;
  // The first frame with an estimate of its own: while the delayed initialisation's window is
  // open (Options::bootstrap_rotation) the filter holds the prior.
  int start_frame = -1;
  for (const calib::FrameEstimate& h : history)
    if (!history.empty() && h.covariance(0, 0) < 0.99 * history.front().covariance(0, 0)) {
      start_frame = h.frame;
      break;
    }
  for (int k = 0; k < 3; ++k) {
    PlotSeries est{"estimate", {}, {}, plot_color(0), false, false};
    PlotSeries hi{"+-3 sigma", {}, {}, plot_color(0), false, true};
    PlotSeries lo{"-3 sigma", {}, {}, plot_color(0), false, true};
    PlotSeries sig{"sigma", {}, {}, plot_color(1), false, false};
    double vmin = std::numeric_limits<double>::infinity(), vmax = -vmin;
    for (const calib::FrameEstimate& h : history) {
      const double v = h.extrinsics.vec()(k) * scale[k];
      const double s = std::sqrt(std::max(h.covariance(k, k), 0.0)) * scale[k];
      if (!std::isfinite(v) || !std::isfinite(s)) continue;
      est.x.push_back(h.frame), est.y.push_back(v);
      hi.x.push_back(h.frame), hi.y.push_back(v + 3 * s);
      lo.x.push_back(h.frame), lo.y.push_back(v - 3 * s);
      sig.x.push_back(h.frame), sig.y.push_back(s);
      vmin = std::min(vmin, v), vmax = std::max(vmax, v);
    }
    lo.name.clear();  // one legend entry for both bands
    std::vector<PlotSeries> s{est, hi, lo};
    const double x0 = history.empty() ? 0.0 : history.front().frame;
    const double x1 = history.empty() ? 1.0 : std::max<double>(history.back().frame, x0 + 1);
    if (truth) {
      const double t = truth->vec()(k) * scale[k];
      s.push_back({"ground truth", {x0, x1}, {t, t}, plot_color(2), false, true});
      vmin = std::min(vmin, t), vmax = std::max(vmax, t);
    }
    if (refined) {
      const double r = refined->vec()(k) * scale[k];
      s.push_back({"refined (batch)", {x0, x1}, {r, r}, plot_color(3), false, false});
      vmin = std::min(vmin, r), vmax = std::max(vmax, r);
    }
    PlotOptions o;
    o.title = k == 0 ? "phi" : k == 1 ? "rho" : "psi";
    o.x_label = "frame";
    o.y_label = names[k];
    o.width = 560, o.height = 400;
    o.x_lo = x0, o.x_hi = x1;
    if (std::isfinite(vmin)) {
      // The estimate's own range (the +-3 sigma bands of the prior would flatten it).
      const double pad = std::max(0.1 * (vmax - vmin), k == 1 ? 2.0 : 0.5);
      o.y_lo = vmin - pad, o.y_hi = vmax + pad;
    }
    o.legend_bottom = true;
    if (start_frame >= 0) {
      o.vertical_lines = {static_cast<double>(start_frame)};
      o.vertical_labels = {"first estimate"};
    }
    top.push_back(draw_plot(s, o));
    PlotOptions os;
    os.title = std::string("sigma of ") + (k == 0 ? "phi" : k == 1 ? "rho" : "psi");
    os.x_label = "frame";
    os.y_label = sig_names[k];
    os.width = 560, os.height = 300;
    os.x_lo = x0, os.x_hi = x1;
    os.log_y = true;  // the prior's sigma and the final one are orders of magnitude apart
    os.vertical_lines = o.vertical_lines;
    bottom.push_back(draw_plot({sig}, os));
  }
  cv::Mat a, b, out;
  cv::hconcat(top, a);
  cv::hconcat(bottom, b);
  cv::vconcat(a, b, out);
  return out;
}

}  // namespace omnivert::viz
