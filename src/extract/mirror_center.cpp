#include "omnivert/extract/mirror_center.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

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
  return true;
}

MirrorCenterDetector::MirrorCenterDetector(MirrorCenterOptions options)
    : options_(std::move(options)) {}

void MirrorCenterDetector::set_mask(const cv::Mat& usable) {
  CV_Assert(usable.empty() || usable.type() == CV_8UC1);
  usable_ = usable.empty() || mask_all_usable(usable) ? cv::Mat() : erode_mask(usable, 1);
}

namespace {

void set_why(std::string* why, const std::string& m) {
  if (why) *why = m;
}

// Bilinear sample of an 8-bit image; false outside.
inline bool sample(const cv::Mat& img, double x, double y, double& out) {
  if (x < 0 || y < 0 || x > img.cols - 1.001 || y > img.rows - 1.001) return false;
  const int x0 = static_cast<int>(x);
  const int y0 = static_cast<int>(y);
  const double fx = x - x0;
  const double fy = y - y0;
  const uchar* r0 = img.ptr<uchar>(y0);
  const uchar* r1 = img.ptr<uchar>(y0 + 1);
  out =
      (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
  return true;
}

// Least-squares circle through points: algebraic (Kasa) start, then Gauss-Newton on the
// geometric distance, with outliers beyond 3 robust sigmas removed between passes.
bool fit_circle(std::vector<Eigen::Vector2d> pts, Eigen::Vector2d& c, double& r) {
  for (int pass = 0; pass < 3; ++pass) {
    if (pts.size() < 8) return false;
    if (pass == 0) {
      Eigen::MatrixXd A(pts.size(), 3);
      Eigen::VectorXd b(pts.size());
      for (std::size_t i = 0; i < pts.size(); ++i) {
        A(i, 0) = pts[i].x();
        A(i, 1) = pts[i].y();
        A(i, 2) = 1.0;
        b(i) = -(pts[i].squaredNorm());
      }
      const Eigen::Vector3d s = A.colPivHouseholderQr().solve(b);
      c = Eigen::Vector2d(-s(0) / 2, -s(1) / 2);
      const double rr = c.squaredNorm() - s(2);
      if (!(rr > 0)) return false;
      r = std::sqrt(rr);
    }
    for (int it = 0; it < 10; ++it) {
      Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
      Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
      for (const auto& p : pts) {
        const Eigen::Vector2d d = p - c;
        const double n = d.norm();
        if (n < 1e-9) continue;
        const double res = n - r;
        const Eigen::Vector3d J(-d.x() / n, -d.y() / n, -1.0);
        JtJ += J * J.transpose();
        Jtr += J * res;
      }
      const Eigen::Vector3d delta = JtJ.ldlt().solve(-Jtr);
      c += delta.head<2>();
      r += delta(2);
      if (delta.norm() < 1e-6) break;
    }
    std::vector<double> res;
    res.reserve(pts.size());
    for (const auto& p : pts) res.push_back(std::abs((p - c).norm() - r));
    std::vector<double> sorted = res;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double gate = std::max(0.5, 3.0 * 1.4826 * sorted[sorted.size() / 2]);
    std::vector<Eigen::Vector2d> kept;
    kept.reserve(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (res[i] <= gate) kept.push_back(pts[i]);
    if (kept.size() == pts.size()) break;
    pts.swap(kept);
  }
  return std::isfinite(c.x()) && std::isfinite(c.y()) && std::isfinite(r) && r > 0;
}

// Smooths an accumulator and returns the position of its maximum (with a parabolic sub-pixel
// step in each axis).
Eigen::Vector2d accumulator_peak(cv::Mat& acc, double sigma) {
  cv::GaussianBlur(acc, acc, cv::Size(), sigma);
  cv::Point loc;
  cv::minMaxLoc(acc, nullptr, nullptr, nullptr, &loc);
  double dx = 0, dy = 0;
  if (loc.x > 0 && loc.x < acc.cols - 1) {
    const float l = acc.at<float>(loc.y, loc.x - 1), m = acc.at<float>(loc.y, loc.x),
                r = acc.at<float>(loc.y, loc.x + 1);
    const double den = l - 2 * m + r;
    if (den < 0) dx = 0.5 * (l - r) / den;
  }
  if (loc.y > 0 && loc.y < acc.rows - 1) {
    const float u = acc.at<float>(loc.y - 1, loc.x), m = acc.at<float>(loc.y, loc.x),
                d = acc.at<float>(loc.y + 1, loc.x);
    const double den = u - 2 * m + d;
    if (den < 0) dy = 0.5 * (u - d) / den;
  }
  return {loc.x + dx, loc.y + dy};
}

// Fraction of the in-image circumference at each integer radius covered by edge pixels with
// a radial gradient of the given sign (+1: brighter outward, -1: darker outward).
std::vector<double> radial_edge_coverage(const cv::Mat& gx,
                                         const cv::Mat& gy,
                                         const Eigen::Vector2d& c,
                                         int r_max,
                                         double threshold,
                                         int sign,
                                         const cv::Mat& usable) {
  std::vector<double> hits(r_max + 2, 0.0), total(r_max + 2, 0.0);
  const double t2 = threshold * threshold;
  const double cos20 = std::cos(deg2rad(20.0));
  for (int v = 1; v < gx.rows - 1; ++v) {
    const short* px = gx.ptr<short>(v);
    const short* py = gy.ptr<short>(v);
    const uchar* ok = usable.empty() ? nullptr : usable.ptr<uchar>(v);
    for (int u = 1; u < gx.cols - 1; ++u) {
      if (ok && !ok[u]) continue;  // masked: neither on the circumference nor a hit
      const double dx = u - c.x(), dy = v - c.y();
      const double rr = std::sqrt(dx * dx + dy * dy);
      const int ri = static_cast<int>(rr + 0.5);
      if (ri > r_max || ri < 1) continue;
      total[ri] += 1.0;
      const double g2 = double(px[u]) * px[u] + double(py[u]) * py[u];
      if (g2 < t2) continue;
      const double radial = (px[u] * dx + py[u] * dy) / rr;  // gradient along r-hat
      if (sign * radial >= cos20 * std::sqrt(g2)) hits[ri] += 1.0;
    }
  }
  std::vector<double> cov(r_max + 2, 0.0);
  for (int r = 1; r <= r_max; ++r) {
    // Circumference pixels at radius r number about 2 pi r; the ring of pixels rounding to
    // r has that many, and an edge is about one pixel thick.
    if (total[r] > 0.25 * kTwoPi * r) cov[r] = hits[r] / total[r];
  }
  // Smooth over +-1 pixel: an edge between two pixel rings splits its votes.
  std::vector<double> sm(cov.size(), 0.0);
  for (std::size_t r = 1; r + 1 < cov.size(); ++r) sm[r] = cov[r - 1] + cov[r] + cov[r + 1];
  return sm;
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

bool MirrorCenterDetector::usable_at(const Eigen::Vector2d& p) const {
  // The four pixels of the bilinear sample (inside the image: sample() checked it).
  const int x0 = static_cast<int>(p.x()), y0 = static_cast<int>(p.y());
  const uchar* r0 = usable_.ptr<uchar>(y0);
  const uchar* r1 = usable_.ptr<uchar>(y0 + 1);
  return r0[x0] && r0[x0 + 1] && r1[x0] && r1[x0 + 1];
}

bool MirrorCenterDetector::refine(const cv::Mat& gray,
                                  Eigen::Vector2d& center,
                                  double& rim_radius) const {
  const double step = 0.5;
  const double W = options_.rim_window;
  const int n = static_cast<int>(2 * W / step) + 1;
  std::vector<double> prof(n);
  const bool masked = !usable_.empty();
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<Eigen::Vector2d> pts[2];  // [0]: darker outward, [1]: brighter outward
    double strength[2] = {0, 0};
    for (int k = 0; k < options_.rim_rays; ++k) {
      const double a = kTwoPi * k / options_.rim_rays;
      const Eigen::Vector2d d(std::cos(a), std::sin(a));
      bool ok = true;
      for (int i = 0; i < n && ok; ++i) {
        const Eigen::Vector2d p = center + (rim_radius - W + i * step) * d;
        ok = sample(gray, p.x(), p.y(), prof[i]) && (!masked || usable_at(p));
      }
      if (!ok) continue;
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
    if (!fit_circle(pts[s], c, r)) return false;
    center = c;
    rim_radius = r;
  }
  return true;
}

std::optional<MirrorCircle> MirrorCenterDetector::estimate(const cv::Mat& gray,
                                                           const CameraGeometry& geometry,
                                                           std::string* why) const {
  CV_Assert(gray.type() == CV_8UC1);
  // Work on a copy no larger than 640 pixels across for the coarse search.
  const double scale = std::min(1.0, 640.0 / std::max(gray.cols, gray.rows));
  cv::Mat small;
  if (scale < 1.0)
    cv::resize(gray, small, cv::Size(), scale, scale, cv::INTER_AREA);
  else
    small = gray;
  CV_Assert(usable_.empty() || usable_.size() == gray.size());
  const cv::Mat small_usable = shrink_mask(usable_, small.size());
  cv::Mat gx, gy;
  cv::Sobel(small, gx, CV_16S, 1, 0, 3);
  cv::Sobel(small, gy, CV_16S, 0, 1, 3);
  const double thr = options_.edge_threshold;

  Eigen::Vector2d c;
  if (geometry.center) {
    c = *geometry.center * scale;
  } else {
    // Gradient lines of every circular edge around the mirror axis (rim, self-reflection,
    // concentric floor/ceiling structure) pass through the centre: vote along them.
    cv::Mat acc = cv::Mat::zeros(small.size(), CV_32F);
    const int reach = std::max(small.cols, small.rows);
    const double t2 = thr * thr;
    for (int v = 1; v < small.rows - 1; v += 1) {
      const short* px = gx.ptr<short>(v);
      const short* py = gy.ptr<short>(v);
      const uchar* ok = small_usable.empty() ? nullptr : small_usable.ptr<uchar>(v);
      for (int u = 1; u < small.cols - 1; u += 1) {
        const double g2 = double(px[u]) * px[u] + double(py[u]) * py[u];
        if (g2 < t2) continue;
        if (ok && !ok[u]) continue;  // masked pixels cast no vote
        const double g = std::sqrt(g2);
        const double ex = px[u] / g, ey = py[u] / g;
        for (int sgn = -1; sgn <= 1; sgn += 2) {
          for (int t = 8; t < reach; t += 1) {
            const int x = static_cast<int>(u + sgn * t * ex + 0.5);
            const int y = static_cast<int>(v + sgn * t * ey + 0.5);
            if (x < 0 || y < 0 || x >= acc.cols || y >= acc.rows) break;
            acc.at<float>(y, x) += 1.0f;
          }
        }
      }
    }
    c = accumulator_peak(acc, 2.0);
  }

  // Rim: radii with a good coverage of darker-outward radial edges, best first; the first
  // that fits to sub-pixel precision is the rim (a mirror holder can add rings that lie
  // mostly outside the image).
  const int rmax_search = static_cast<int>(std::hypot(small.cols, small.rows) / 2);
  const auto outer = radial_edge_coverage(gx, gy, c, rmax_search, thr, -1, small_usable);
  std::vector<std::pair<double, int>> rims;  // (coverage, radius in the small image)
  int r_lo = static_cast<int>(0.15 * std::min(small.cols, small.rows)), r_hi = rmax_search;
  if (geometry.r_max) {
    // Rim just outside the given r_max: look in the next 15%.
    r_lo = static_cast<int>(*geometry.r_max * scale);
    r_hi = std::min(rmax_search, static_cast<int>(*geometry.r_max * scale * 1.15 + 3));
  }
  for (int r = std::max(r_lo, 2); r < r_hi; ++r) {
    if (outer[r] >= 0.3 && outer[r] >= outer[r - 1] && outer[r] > outer[r + 1])
      rims.emplace_back(outer[r], r);
  }
  std::sort(rims.rbegin(), rims.rend());
  Eigen::Vector2d center = c / scale;
  double rim_radius = 0;
  bool refined = false;
  for (std::size_t i = 0; i < rims.size() && i < 6 && !refined; ++i) {
    center = c / scale;
    rim_radius = rims[i].second / scale;
    refined = refine(gray, center, rim_radius);
  }
  if (!refined) {
    if (!geometry.r_max) {
      set_why(why,
              rims.empty() ? "no mirror rim found (no circle of darker-outward edges around the "
                             "centre); give center, r_min and r_max in sensor.yaml"
                           : "the mirror rim was found but could not be fitted to sub-pixel "
                             "precision; give center, r_min and r_max in sensor.yaml");
      return std::nullopt;
    }
    if (!geometry.center) {
      set_why(why, "the mirror rim could not be fitted; give center in sensor.yaml");
      return std::nullopt;
    }
    center = *geometry.center;
    rim_radius = 0;  // no rim: the centre stays where sensor.yaml puts it
  }
  if (geometry.center && !refined) center = *geometry.center;
  const double rim = rim_radius * scale;

  MirrorCircle circle;
  circle.center = center;
  circle.rim_radius = rim_radius;
  circle.r_max =
      geometry.r_max ? *geometry.r_max : rim_radius * (1.0 - options_.rim_margin_fraction);
  if (geometry.r_min) {
    circle.r_min = *geometry.r_min;
  } else {
    // The camera's own reflection: a dark disc, so brighter-outward circular edges.
    const auto inner =
        radial_edge_coverage(gx, gy, center * scale, rmax_search, thr, +1, small_usable);
    double best = 0;
    int disc = 0;
    for (int r = static_cast<int>(0.05 * rim); r <= static_cast<int>(0.5 * rim); ++r)
      if (inner[r] > best) best = inner[r], disc = r;
    circle.r_min =
        best >= 0.3 ? (disc / scale) * (1.0 + options_.inner_margin_fraction) : 0.25 * circle.r_max;
  }
  if (!(circle.r_min < circle.r_max)) {
    set_why(why, "estimated r_min is not below r_max; give r_min and r_max in sensor.yaml");
    return std::nullopt;
  }
  return circle;
}

std::optional<MirrorCircle> MirrorCenterDetector::detect(const cv::Mat& gray,
                                                         const MirrorCircle& prior,
                                                         std::string* why) const {
  CV_Assert(gray.type() == CV_8UC1);
  CV_Assert(usable_.empty() || usable_.size() == gray.size());
  const double R = prior.rim_radius;
  if (!(R > 0)) {
    set_why(why, "no rim radius known: call estimate() on a first frame");
    return std::nullopt;
  }
  const double S = options_.search_radius;
  // Band of the image that can hold the rim.
  const double reach = R + S + 3;
  const cv::Rect roi = cv::Rect(static_cast<int>(prior.center.x() - reach),
                                static_cast<int>(prior.center.y() - reach),
                                static_cast<int>(2 * reach) + 1,
                                static_cast<int>(2 * reach) + 1) &
                       cv::Rect(0, 0, gray.cols, gray.rows);
  cv::Mat gx, gy;
  cv::Sobel(gray(roi), gx, CV_16S, 1, 0, 3);
  cv::Sobel(gray(roi), gy, CV_16S, 0, 1, 3);
  const int A = static_cast<int>(std::ceil(S)) + 3;
  cv::Mat acc = cv::Mat::zeros(2 * A + 1, 2 * A + 1, CV_32F);
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
      for (int sgn = -1; sgn <= 1; sgn += 2) {
        const double cx = x + sgn * R * px[u] / g - prior.center.x();
        const double cy = y + sgn * R * py[u] / g - prior.center.y();
        const int ix = static_cast<int>(std::lround(cx)) + A;
        const int iy = static_cast<int>(std::lround(cy)) + A;
        if (ix >= 0 && iy >= 0 && ix < acc.cols && iy < acc.rows) acc.at<float>(iy, ix) += 1.0f;
      }
    }
  }
  const Eigen::Vector2d peak = accumulator_peak(acc, 1.0);
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
