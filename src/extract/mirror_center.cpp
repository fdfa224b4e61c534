#include "omnivert/extract/mirror_center.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "extract/rim_geometry.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/image/image_mask.hpp"

namespace omnivert {

bool MirrorCenterOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!(edge_threshold > 0)) return fail("edge_threshold must be positive");
  if (!(search_radius >= 1)) return fail("search_radius must be at least 1 pixel");
  if (rim_rays < 16) return fail("rim_rays must be at least 16");
  if (!(rim_window >= 2)) return fail("rim_window must be at least 2 pixels");
  if (!(rim_margin_fraction >= 0 && rim_margin_fraction < 0.5))
    return fail("rim_margin_fraction must be in [0, 0.5)");
  if (!(inner_margin_fraction >= 0 && inner_margin_fraction < 1))
    return fail("inner_margin_fraction must be in [0, 1)");
  if (!(track_px >= 0)) return fail("track_px must not be negative");
  return true;
}

MirrorCenterDetector::MirrorCenterDetector(MirrorCenterOptions options)
    : options_(std::move(options)) {}

namespace {

void set_why(std::string* why, const std::string& m) {
  if (why) *why = m;
}

// The usable mask of a reduced image: a small pixel is usable when all the pixels it averages
// are, and its Sobel window is then shrunk by one small pixel. Empty stays empty.
cv::Mat shrink_mask(const cv::Mat& usable, cv::Size small) {
  if (usable.empty() || usable.size() == small) return usable;
  cv::Mat s;
  cv::resize(usable, s, small, 0, 0, cv::INTER_AREA);
  cv::compare(s, 255, s, cv::CMP_GE);
  return erode_mask(s, 1);
}

}  // namespace

void MirrorCenterDetector::set_mask(const cv::Mat& usable) {
  CV_Assert(usable.empty() || usable.type() == CV_8UC1);
  usable_ = usable.empty() || mask_all_usable(usable) ? cv::Mat() : erode_mask(usable, 1);
}

bool MirrorCenterDetector::refine(const cv::Mat& gray,
                                  Eigen::Vector2d& center,
                                  double& rim_radius) const {
  const double step = 0.5;
  const double W = options_.rim_window;
  const int n = static_cast<int>(2 * W / step) + 1;
  std::vector<double> prof(n);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<Eigen::Vector2d> pts[2];  // [0]: darker outward, [1]: brighter outward
    double strength[2] = {0, 0};
    for (int k = 0; k < options_.rim_rays; ++k) {
      const double a = kTwoPi * k / options_.rim_rays;
      const Eigen::Vector2d d(std::cos(a), std::sin(a));
      bool ok = true;
      for (int i = 0; i < n && ok; ++i) {
        const Eigen::Vector2d p = center + (rim_radius - W + i * step) * d;
        ok = rim::sample(gray, p.x(), p.y(), prof[i]) &&
             (usable_.empty() || rim::usable_at(usable_, p));
      }
      if (!ok) continue;  // outside the image or masked
      for (int s = 0; s < 2; ++s) {
        const double sgn = s == 0 ? -1.0 : 1.0;
        int best = -1;
        double best_v = 0;
        for (int i = 1; i + 1 < n; ++i) {
          const double der = sgn * (prof[i + 1] - prof[i - 1]) / (2 * step);
          if (der > best_v) {
            best_v = der;
            best = i;
          }
        }
        if (best < 2 || best > n - 3 || best_v < 4.0) continue;
        auto der_at = [&](int i) { return sgn * (prof[i + 1] - prof[i - 1]) / (2 * step); };
        const double l = der_at(best - 1), m = der_at(best), r = der_at(best + 1);
        const double den = l - 2 * m + r;
        const double off = den < 0 ? 0.5 * (l - r) / den : 0.0;
        const double rad = rim_radius - W + (best + off) * step;
        pts[s].push_back(center + rad * d);
        strength[s] += best_v;
      }
    }
    const int s = strength[0] >= strength[1] ? 0 : 1;
    if (static_cast<int>(pts[s].size()) < options_.rim_rays / 4) return false;
    Eigen::Vector2d c = center;
    double r = rim_radius;
    if (!rim::fit_circle(pts[s], c, r)) return false;
    center = c;
    rim_radius = r;
  }
  return true;
}

namespace {

std::optional<rim::RimFit> find_rim(const cv::Mat& gray,
                                    const CameraGeometry& geometry,
                                    const MirrorCenterOptions& options_,
                                    const cv::Mat& usable,
                                    std::string* why) {
  // Candidate circles (centre, radius) on a copy no larger than 320 pixels across.
  const double scale = std::min(1.0, 320.0 / std::max(gray.cols, gray.rows));
  cv::Mat small;
  if (scale < 1.0)
    cv::resize(gray, small, cv::Size(), scale, scale, cv::INTER_AREA);
  else
    small = gray;
  const cv::Mat small_usable = shrink_mask(usable, small.size());
  const int diag = static_cast<int>(std::hypot(small.cols, small.rows) / 2);
  // The rim is larger than the self-reflection: at least 30% of the image's smaller side.
  int r_lo = static_cast<int>(0.3 * std::min(small.cols, small.rows)), r_hi = diag;
  if (geometry.r_max) {
    // Rim just outside the given r_max: look in the next 15%.
    r_lo = static_cast<int>(*geometry.r_max * scale);
    r_hi = std::min(diag, static_cast<int>(*geometry.r_max * scale * 1.15 + 3));
  }
  std::vector<rim::CircleCandidate> cands;
  if (geometry.center) {
    cv::Mat gx, gy;
    cv::Sobel(small, gx, CV_16S, 1, 0, 3);
    cv::Sobel(small, gy, CV_16S, 0, 1, 3);
    const Eigen::Vector2d c = *geometry.center * scale;
    const auto cov =
        rim::radial_edge_coverage(gx, gy, c, diag, options_.edge_threshold, 0, small_usable);
    for (int r = std::max(r_lo, 2); r < std::min(r_hi, diag); ++r)
      if (cov[r] >= 0.3 && cov[r] >= cov[r - 1] && cov[r] > cov[r + 1])
        cands.push_back({c, double(r), cov[r]});
    std::sort(
        cands.begin(), cands.end(), [](const auto& x, const auto& y) { return x.score > y.score; });
    if (cands.size() > 8) cands.resize(8);
  } else {
    cands = rim::hough_circles(small, r_lo, r_hi, options_.edge_threshold, 30, 6.0, small_usable);
  }
  // Each candidate is refined on rays at full resolution; the rim is the candidate found
  // within 1 px on the most rays, on at least 30% of its visible circumference, with enough
  // arc to fix a centre (a mirror holder's ring cut by the frame loses to the rim inside it).
  std::optional<rim::RimFit> best;
  const int min_points = options_.rim_rays / 4;
  for (const auto& cand : cands) {
    rim::RimFit fit;
    Eigen::Vector2d c = cand.center / scale;
    double r = cand.radius / scale;
    double window = std::max(options_.rim_window, 2.0 / scale + 2.0);
    bool ok = true;
    for (int pass = 0; pass < 3 && ok; ++pass) {
      ok = rim::fit_rim_on_rays(gray, c, r, window, options_.rim_rays, fit, usable);
      c = fit.center;
      r = fit.radius;
      window = options_.rim_window;
    }
    if (!ok || fit.inliers < min_points || fit.quadrants < 3 || fit.rms > 2.0) continue;
    if (geometry.center && (fit.center - *geometry.center).norm() > options_.search_radius)
      continue;
    if (fit.coverage() >= 0.3 && (!best || fit.close > best->close)) best = fit;
  }
  if (!best) {
    set_why(why,
            "no mirror rim found (no circle of edges, darker or brighter outward, on enough of "
            "its visible arc around a centre inside the image); give center, r_min and r_max "
            "in cam0/sensor.yaml, or run `omnivert camera` on several frames to estimate them");
    return std::nullopt;
  }
  return best;
}

}  // namespace

std::optional<MirrorCircle> MirrorCenterDetector::estimate(const cv::Mat& gray,
                                                           const CameraGeometry& geometry,
                                                           std::string* why) const {
  CV_Assert(gray.type() == CV_8UC1);
  std::string reason;
  const auto fit = find_rim(gray, geometry, options_, usable_, &reason);
  Eigen::Vector2d center;
  double rim_radius = 0;
  if (fit) {
    center = fit->center;
    rim_radius = fit->radius;
  } else if (geometry.center && geometry.r_max) {
    center = *geometry.center;  // no rim: the centre stays where sensor.yaml puts it
  } else {
    set_why(why, reason);
    return std::nullopt;
  }
  if (geometry.center) center = *geometry.center;

  MirrorCircle circle;
  circle.center = center;
  circle.rim_radius = rim_radius;
  circle.r_max =
      geometry.r_max ? *geometry.r_max : rim_radius * (1.0 - options_.rim_margin_fraction);
  if (geometry.r_min) {
    circle.r_min = *geometry.r_min;
  } else {
    circle.r_min = self_reflection_radius(gray, center, circle.r_max);
  }
  if (!(circle.r_min < circle.r_max)) {
    set_why(why, "estimated r_min is not below r_max; give r_min and r_max in sensor.yaml");
    return std::nullopt;
  }
  return circle;
}

double MirrorCenterDetector::self_reflection_radius(const cv::Mat& gray,
                                                    const Eigen::Vector2d& center,
                                                    double r_max) const {
  const double scale = std::min(1.0, 640.0 / std::max(gray.cols, gray.rows));
  cv::Mat small;
  if (scale < 1.0)
    cv::resize(gray, small, cv::Size(), scale, scale, cv::INTER_AREA);
  else
    small = gray;
  cv::Mat gx, gy;
  cv::Sobel(small, gx, CV_16S, 1, 0, 3);
  cv::Sobel(small, gy, CV_16S, 0, 1, 3);
  // The camera's own reflection: a dark disc, so brighter-outward circular edges.
  const int rmax_search = static_cast<int>(std::hypot(small.cols, small.rows) / 2);
  const auto inner = rim::radial_edge_coverage(gx,
                                               gy,
                                               center * scale,
                                               rmax_search,
                                               options_.edge_threshold,
                                               +1,
                                               shrink_mask(usable_, small.size()));
  const double rim = r_max * scale;
  double best = 0;
  int disc = 0;
  for (int r = static_cast<int>(0.05 * rim); r <= static_cast<int>(0.5 * rim); ++r)
    if (r < static_cast<int>(inner.size()) && inner[r] > best) best = inner[r], disc = r;
  return best >= 0.3 ? (disc / scale) * (1.0 + options_.inner_margin_fraction) : 0.25 * r_max;
}

namespace {
// The two centres an edge pixel at (x, y) with gradient (gx, gy), |g| = g, votes for: R along
// its gradient on either side of the edge, as offsets from `prior` binned in acc (middle A).
void vote_centres(double x,
                  double y,
                  short gx,
                  short gy,
                  double g,
                  double R,
                  const Eigen::Vector2d& prior,
                  int A,
                  cv::Mat& acc) {
  for (int sgn = -1; sgn <= 1; sgn += 2) {
    const double cx = x + sgn * R * gx / g - prior.x();
    const double cy = y + sgn * R * gy / g - prior.y();
    const int ix = static_cast<int>(std::lround(cx)) + A;
    const int iy = static_cast<int>(std::lround(cy)) + A;
    if (ix >= 0 && iy >= 0 && ix < acc.cols && iy < acc.rows) acc.at<float>(iy, ix) += 1.0f;
  }
}
}  // namespace

void MirrorCenterDetector::vote_band(const cv::Mat& gray,
                                     const MirrorCircle& prior,
                                     const cv::Rect& roi,
                                     int A,
                                     cv::Mat& acc) const {
  // vote_band_reference on the band's runs of pixels only, each pixel's Sobel computed where
  // it is needed (the same integers as OpenCV's inside the square).
  const double R = prior.rim_radius, S = options_.search_radius;
  const double t2 = options_.edge_threshold * options_.edge_threshold;
  const double band_lo = std::max(0.0, R - S - 2), band_hi = R + S + 2;
  const int W = gray.cols;
  for (int v = 1; v < roi.height - 1; ++v) {
    const double y = roi.y + v;
    const double dy = y - prior.center.y();
    // Only the columns of this row within the band can vote: up to two runs, [-o, -i] and
    // [i, o] about the centre's column (a margin of a pixel; the test below decides).
    if (std::abs(dy) > band_hi + 1) continue;
    const double outer = std::sqrt(std::max(0.0, band_hi * band_hi - dy * dy)) + 1;
    const double inner = std::abs(dy) < band_lo - 1
                             ? std::sqrt(band_lo * band_lo - dy * dy) - 1
                             : -1.0;  // the row crosses the inner circle: one run
    const double cxr = prior.center.x() - roi.x;
    const int lo = std::max(1, static_cast<int>(std::floor(cxr - outer)));
    const int hi = std::min(roi.width - 2, static_cast<int>(std::ceil(cxr + outer)));
    const int gap_lo = inner > 0 ? static_cast<int>(std::ceil(cxr - inner)) : hi + 1;
    const int gap_hi = inner > 0 ? static_cast<int>(std::floor(cxr + inner)) : hi;
    const uchar* row = gray.ptr<uchar>(roi.y + v) + roi.x;
    const uchar* ok = usable_.empty() ? nullptr : usable_.ptr<uchar>(roi.y + v) + roi.x;
    for (int u = lo; u <= hi; ++u) {
      if (u > gap_lo && u < gap_hi) u = gap_hi;  // skip the disc inside the band
      const double x = roi.x + u;
      const double dx = x - prior.center.x();
      const double d2 = dx * dx + dy * dy;
      if (d2 < band_lo * band_lo || d2 > band_hi * band_hi) continue;
      // Sobel, eq. (1) (the 3x3 window lies inside the band's rectangle).
      const uchar* p = row + u;
      const short gxu = static_cast<short>((p[-W + 1] + 2 * p[1] + p[W + 1]) -
                                           (p[-W - 1] + 2 * p[-1] + p[W - 1]));
      const short gyu = static_cast<short>((p[W - 1] + 2 * p[W] + p[W + 1]) -
                                           (p[-W - 1] + 2 * p[-W] + p[-W + 1]));
      const double g2 = double(gxu) * gxu + double(gyu) * gyu;
      if (g2 < t2) continue;
      if (ok && !ok[u]) continue;  // masked pixels cast no vote
      const double g = std::sqrt(g2);
      vote_centres(x, y, gxu, gyu, g, R, prior.center, A, acc);
    }
  }
}

void MirrorCenterDetector::vote_band_reference(const cv::Mat& gray,
                                               const MirrorCircle& prior,
                                               const cv::Rect& roi,
                                               int A,
                                               cv::Mat& acc) const {
  const double R = prior.rim_radius, S = options_.search_radius;
  cv::Mat gx, gy;
  cv::Sobel(gray(roi), gx, CV_16S, 1, 0, 3);
  cv::Sobel(gray(roi), gy, CV_16S, 0, 1, 3);
  const double t2 = options_.edge_threshold * options_.edge_threshold;
  const double band_lo = std::max(0.0, R - S - 2), band_hi = R + S + 2;
  for (int v = 1; v < roi.height - 1; ++v) {
    const short* px = gx.ptr<short>(v);
    const short* py = gy.ptr<short>(v);
    const double y = roi.y + v;
    const uchar* ok = usable_.empty() ? nullptr : usable_.ptr<uchar>(roi.y + v) + roi.x;
    for (int u = 1; u < roi.width - 1; ++u) {
      const double x = roi.x + u;
      const double dx = x - prior.center.x(), dy = y - prior.center.y();
      const double d2 = dx * dx + dy * dy;
      if (d2 < band_lo * band_lo || d2 > band_hi * band_hi) continue;
      const double g2 = double(px[u]) * px[u] + double(py[u]) * py[u];
      if (g2 < t2) continue;
      if (ok && !ok[u]) continue;  // masked pixels cast no vote
      const double g = std::sqrt(g2);
      vote_centres(x, y, px[u], py[u], g, R, prior.center, A, acc);
    }
  }
}

std::optional<MirrorCircle> MirrorCenterDetector::detect(const cv::Mat& gray,
                                                         const MirrorCircle& prior,
                                                         std::string* why) const {
  CV_Assert(gray.type() == CV_8UC1);
  const double R = prior.rim_radius;
  if (!(R > 0)) {
    set_why(why, "no rim radius known: call estimate() on a first frame");
    return std::nullopt;
  }
  if (options_.track_px > 0) {
    // Tracked: the rim fitted from the prior centre, kept when it moved little.
    Eigen::Vector2d center = prior.center;
    double rim = R;
    if (refine(gray, center, rim) && (center - prior.center).norm() <= options_.track_px &&
        std::abs(rim - R) <= options_.track_px) {
      MirrorCircle out = prior;
      out.center = center;
      out.rim_radius = rim;
      return out;
    }
  }
  const double S = options_.search_radius;
  // Band of the image that can hold the rim.
  const double reach = R + S + 3;
  const cv::Rect roi = cv::Rect(static_cast<int>(prior.center.x() - reach),
                                static_cast<int>(prior.center.y() - reach),
                                static_cast<int>(2 * reach) + 1,
                                static_cast<int>(2 * reach) + 1) &
                       cv::Rect(0, 0, gray.cols, gray.rows);
  const int A = static_cast<int>(std::ceil(S)) + 3;
  cv::Mat acc = cv::Mat::zeros(2 * A + 1, 2 * A + 1, CV_32F);
  if (options_.reference)
    vote_band_reference(gray, prior, roi, A, acc);
  else
    vote_band(gray, prior, roi, A, acc);
  const Eigen::Vector2d peak = rim::accumulator_peak(acc, 1.0);
  Eigen::Vector2d center = prior.center + peak - Eigen::Vector2d(A, A);
  double rim = R;
  if (!refine(gray, center, rim)) {
    set_why(why, "mirror rim not found near the expected centre");
    return std::nullopt;
  }
  MirrorCircle out = prior;
  out.center = center;
  out.rim_radius = rim;
  return out;
}

}  // namespace omnivert
