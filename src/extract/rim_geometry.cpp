#include "extract/rim_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"

namespace omnivert::rim {

// Bilinear sample of an 8-bit image; false outside.
bool sample(const cv::Mat& img, double x, double y, double& out) {
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
bool fit_circle(std::vector<Eigen::Vector2d> pts,
                Eigen::Vector2d& c,
                double& r,
                std::vector<Eigen::Vector2d>* kept_out) {
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
  if (kept_out) *kept_out = pts;
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

bool usable_at(const cv::Mat& usable, const Eigen::Vector2d& p) {
  // The four pixels of a bilinear sample at p (inside the image: sample() checked it).
  const int x0 = static_cast<int>(p.x()), y0 = static_cast<int>(p.y());
  const uchar* r0 = usable.ptr<uchar>(y0);
  const uchar* r1 = usable.ptr<uchar>(y0 + 1);
  return r0[x0] && r0[x0 + 1] && r1[x0] && r1[x0 + 1];
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
      const double along = sign == 0 ? std::abs(radial) : sign * radial;
      if (along >= cos20 * std::sqrt(g2)) hits[ri] += 1.0;
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

std::vector<CircleCandidate> hough_circles(const cv::Mat& gray,
                                           int r_lo,
                                           int r_hi,
                                           double threshold,
                                           int count,
                                           double separation,
                                           const cv::Mat& usable) {
  std::vector<CircleCandidate> out;
  r_lo = std::max(r_lo, 2);
  if (r_hi <= r_lo + 2) return out;
  cv::Mat gx, gy;
  cv::Sobel(gray, gx, CV_16S, 1, 0, 3);
  cv::Sobel(gray, gy, CV_16S, 0, 1, 3);
  const int W = gray.cols, H = gray.rows, R = r_hi - r_lo + 1;
  // One 16-bit slice per radius: each edge pixel adds at most one vote to a cell.
  std::vector<cv::Mat> acc(R);
  for (auto& a : acc) a = cv::Mat::zeros(H, W, CV_16U);
  const double t2 = threshold * threshold;
  for (int v = 1; v < H - 1; ++v) {
    const short* px = gx.ptr<short>(v);
    const short* py = gy.ptr<short>(v);
    const uchar* ok = usable.empty() ? nullptr : usable.ptr<uchar>(v);
    for (int u = 1; u < W - 1; ++u) {
      const double g2 = double(px[u]) * px[u] + double(py[u]) * py[u];
      if (g2 < t2) continue;
      if (ok && !ok[u]) continue;  // masked pixels cast no vote
      const double g = std::sqrt(g2);
      const double ex = px[u] / g, ey = py[u] / g;
      for (int k = 0; k < R; ++k) {
        const double r = r_lo + k;
        for (int sgn = -1; sgn <= 1; sgn += 2) {
          const int x = static_cast<int>(std::lround(u + sgn * r * ex));
          const int y = static_cast<int>(std::lround(v + sgn * r * ey));
          if (x < 0 || y < 0 || x >= W || y >= H) continue;
          std::uint16_t& cell = acc[k].at<std::uint16_t>(y, x);
          if (cell < 65535) ++cell;
        }
      }
    }
  }
  // Votes in a 3x3x3 neighbourhood, divided by the radius: a circle's votes and the votes of
  // unrelated edges both grow with its circumference.
  std::vector<cv::Mat> box(R);
  for (int k = 0; k < R; ++k)
    cv::boxFilter(acc[k], box[k], CV_32F, cv::Size(3, 3), {-1, -1}, false);
  std::vector<CircleCandidate> all;
  for (int k = 1; k + 1 < R; ++k) {
    cv::Mat s = box[k - 1] + box[k] + box[k + 1];
    s /= static_cast<double>(r_lo + k);
    // A few local maxima per slice: the best of each 16x16 block.
    const int B = 16;
    for (int by = 0; by < H; by += B) {
      for (int bx = 0; bx < W; bx += B) {
        const cv::Rect blk = cv::Rect(bx, by, B, B) & cv::Rect(0, 0, W, H);
        double m = 0;
        cv::Point loc;
        cv::minMaxLoc(s(blk), nullptr, &m, nullptr, &loc);
        if (m <= 0) continue;
        all.push_back({Eigen::Vector2d(bx + loc.x, by + loc.y), double(r_lo + k), m});
      }
    }
  }
  std::sort(all.begin(), all.end(), [](const CircleCandidate& a, const CircleCandidate& b) {
    return a.score > b.score;
  });
  for (const auto& c : all) {
    bool near = false;
    for (const auto& o : out)
      near = near || ((c.center - o.center).norm() < separation &&
                      std::abs(c.radius - o.radius) < separation);
    if (near) continue;
    out.push_back(c);
    if (static_cast<int>(out.size()) >= count) break;
  }
  return out;
}

bool fit_rim_on_rays(const cv::Mat& gray,
                     const Eigen::Vector2d& center,
                     double radius,
                     double window,
                     int rays,
                     RimFit& out,
                     const cv::Mat& usable) {
  const double step = 0.5;
  const int n = static_cast<int>(2 * window / step) + 1;
  std::vector<double> prof(n), der(n, 0.0);
  std::vector<Eigen::Vector2d> pts;
  out = RimFit{};
  for (int k = 0; k < rays; ++k) {
    const double a = kTwoPi * k / rays;
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    bool ok = true;
    for (int i = 0; i < n && ok; ++i) {
      const Eigen::Vector2d p = center + (radius - window + i * step) * d;
      ok = sample(gray, p.x(), p.y(), prof[i]) && (usable.empty() || usable_at(usable, p));
    }
    if (!ok) continue;  // outside the image or masked: not part of the visible rim
    ++out.rays_inside;
    int best = -1;
    double best_v = 0;
    for (int i = 1; i + 1 < n; ++i) {
      der[i] = std::abs(prof[i + 1] - prof[i - 1]) / (2 * step);
      if (der[i] > best_v) best_v = der[i], best = i;
    }
    if (best < 2 || best > n - 3 || best_v < 4.0) continue;
    const double l = der[best - 1], m = der[best], r = der[best + 1];
    const double den = l - 2 * m + r;
    const double off = den < 0 ? 0.5 * (l - r) / den : 0.0;
    pts.push_back(center + (radius - window + (best + off) * step) * d);
  }
  if (pts.size() < 8) return false;
  out.center = center;
  out.radius = radius;
  if (!fit_circle(pts, out.center, out.radius, &out.points)) return false;
  out.inliers = static_cast<int>(out.points.size());
  double ss = 0;
  bool quadrant[4] = {false, false, false, false};
  for (const auto& p : out.points) {
    const Eigen::Vector2d d = p - out.center;
    const double e = d.norm() - out.radius;
    ss += e * e;
    out.close += std::abs(e) <= 1.0;
    quadrant[(d.x() >= 0 ? 0 : 1) + (d.y() >= 0 ? 0 : 2)] = true;
  }
  out.rms = std::sqrt(ss / std::max(1, out.inliers));
  out.quadrants = quadrant[0] + quadrant[1] + quadrant[2] + quadrant[3];
  return true;
}

}  // namespace omnivert::rim
