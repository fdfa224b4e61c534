#include "omnivert/extract/tilt_estimator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/tilt.hpp"

namespace omnivert {

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// Azimuth in the upright frame of a camera-frame direction.
double upright_azimuth(const Eigen::Matrix3d& R, const Eigen::Vector3d& s) {
  const Eigen::Vector3d v = R * s;
  return std::atan2(v.y(), v.x());
}

// Weighted circular mean of angles (weights 0/1 from mask; all when mask is empty).
double circular_mean(const std::vector<double>& a, const std::vector<char>* mask) {
  double c = 0.0, s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (mask && !mask->empty() && !(*mask)[i]) continue;
    c += std::cos(a[i]);
    s += std::sin(a[i]);
  }
  return std::atan2(s, c);
}

}  // namespace

double TiltEstimate::direction() const {
  return tilt() > 0.0 ? std::atan2(vector.y(), vector.x()) : 0.0;
}
double TiltEstimate::tilt_deg() const { return tilt() * kRadToDeg; }
double TiltEstimate::direction_deg() const { return direction() * kRadToDeg; }

std::string TiltEstimate::describe() const {
  if (!valid) return "tilt: not measured (needs xi, gamma and at least a few lines)";
  char buf[200];
  std::snprintf(buf,
                sizeof buf,
                "tilt %.2f deg (+-%.2f) towards bearing %.1f deg, from %d lines in %d frames",
                tilt_deg(),
                sigma * kRadToDeg,
                direction_deg(),
                lines,
                frames);
  return buf;
}

bool TiltEstimatorOptions::IsValid(std::string* why) const {
  auto fail = [why](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!(corridor_px > 0.0 && inlier_px > 0.0 && inlier_px <= corridor_px))
    return fail("tilt: need 0 < inlier_px <= corridor_px");
  if (min_line_pixels < 3 || min_lines < 2 || iterations < 1)
    return fail("tilt: min_line_pixels >= 3, min_lines >= 2, iterations >= 1");
  if (!(warn_deg >= 0.0)) return fail("tilt: warn_deg must be >= 0");
  return true;
}

TiltEstimator::TiltEstimator(CameraGeometry geometry, TiltEstimatorOptions options)
    : geometry_(std::move(geometry)), options_(options) {}

void TiltEstimator::add_frame(const std::vector<LineExtractor::EdgePoint>& edges,
                              const MirrorCircle& circle,
                              const std::vector<VerticalLine>& lines) {
  ++frames_;
  if (!geometry_.has_projection() || lines.empty()) return;
  const std::size_t first = lines_.size();
  lines_.resize(first + lines.size());
  std::vector<Eigen::Vector2d> dir(lines.size());
  for (std::size_t j = 0; j < lines.size(); ++j) {
    dir[j] = {std::cos(lines[j].image_angle), std::sin(lines[j].image_angle)};
  }
  for (const LineExtractor::EdgePoint& p : edges) {
    const double dx = p.x - circle.center.x(), dy = p.y - circle.center.y();
    const double r = std::hypot(dx, dy);
    if (r < circle.r_min || r > circle.r_max) continue;
    int best = -1;
    double best_lat = options_.corridor_px;
    for (std::size_t j = 0; j < lines.size(); ++j) {
      if (lines[j].polarity != p.polarity) continue;
      const double fwd = dx * dir[j].x() + dy * dir[j].y();
      if (fwd <= 0.0) continue;
      const double lat = std::abs(dx * dir[j].y() - dy * dir[j].x());
      if (lat < best_lat) {
        best_lat = lat;
        best = static_cast<int>(j);
      }
    }
    if (best < 0) continue;
    const double beta = geometry_.bearing_of_image_angle(std::atan2(dy, dx));
    Line& l = lines_[first + static_cast<std::size_t>(best)];
    l.s.push_back(unit_direction(beta, geometry_.elevation_of_radius(r)));
    l.r.push_back(r);
  }
  // Lines with too few pixels cannot constrain anything.
  lines_.erase(std::remove_if(lines_.begin() + static_cast<std::ptrdiff_t>(first),
                              lines_.end(),
                              [&](const Line& l) {
                                return static_cast<int>(l.s.size()) < options_.min_line_pixels;
                              }),
               lines_.end());
}

void TiltEstimator::residuals(const Eigen::Vector2d& x,
                              const std::vector<std::vector<char>>& inlier,
                              std::vector<std::vector<double>>& e) const {
  const Eigen::Matrix3d R = tilt_rotation_of_vector(x);
  e.resize(lines_.size());
  std::vector<double> az;
  for (std::size_t j = 0; j < lines_.size(); ++j) {
    const Line& l = lines_[j];
    az.resize(l.s.size());
    for (std::size_t i = 0; i < l.s.size(); ++i) az[i] = upright_azimuth(R, l.s[i]);
    const double b = circular_mean(az, inlier.empty() ? nullptr : &inlier[j]);
    e[j].resize(l.s.size());
    for (std::size_t i = 0; i < l.s.size(); ++i) e[j][i] = l.r[i] * wrap_angle(az[i] - b);
  }
}

TiltEstimate TiltEstimator::estimate() const {
  TiltEstimate est;
  est.frames = frames_;
  if (!geometry_.has_projection() || static_cast<int>(lines_.size()) < options_.min_lines)
    return est;
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  std::vector<std::vector<char>> inlier;
  std::vector<std::vector<double>> e0, ep, em;
  const double h = 1e-5;
  Eigen::Matrix2d JtJ = Eigen::Matrix2d::Zero();
  double sse = 0.0;
  int n = 0, used = 0;
  for (int it = 0; it < options_.iterations; ++it) {
    // The corridor narrows from corridor_px to inlier_px over the first half.
    const double frac = std::min(1.0, it / std::max(1.0, 0.5 * options_.iterations));
    const double bound = options_.corridor_px + frac * (options_.inlier_px - options_.corridor_px);
    residuals(x, inlier, e0);
    // Inliers: the pixels near their line's curve, about a median-centred azimuth.
    inlier.assign(lines_.size(), {});
    for (std::size_t j = 0; j < lines_.size(); ++j) {
      inlier[j].resize(e0[j].size());
      for (std::size_t i = 0; i < e0[j].size(); ++i) inlier[j][i] = std::abs(e0[j][i]) < bound;
    }
    residuals(x, inlier, e0);
    JtJ.setZero();
    Eigen::Vector2d Jte = Eigen::Vector2d::Zero();
    std::vector<std::vector<double>> d[2];
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector2d dx = Eigen::Vector2d::Zero();
      dx[k] = h;
      residuals(x + dx, inlier, ep);
      residuals(x - dx, inlier, em);
      d[k].resize(lines_.size());
      for (std::size_t j = 0; j < lines_.size(); ++j) {
        d[k][j].resize(ep[j].size());
        for (std::size_t i = 0; i < ep[j].size(); ++i) d[k][j][i] = (ep[j][i] - em[j][i]) / (2 * h);
      }
    }
    sse = 0.0;
    n = 0;
    used = 0;
    for (std::size_t j = 0; j < lines_.size(); ++j) {
      int nj = 0;
      for (char c : inlier[j]) nj += c;
      if (nj < options_.min_line_pixels) continue;
      ++used;
      for (std::size_t i = 0; i < e0[j].size(); ++i) {
        if (!inlier[j][i]) continue;
        const Eigen::Vector2d g(d[0][j][i], d[1][j][i]);
        JtJ += g * g.transpose();
        Jte += g * e0[j][i];
        sse += e0[j][i] * e0[j][i];
        ++n;
      }
    }
    if (used < options_.min_lines || JtJ.determinant() <= 0.0) return est;
    x -= JtJ.ldlt().solve(Jte);
  }
  est.valid = true;
  est.vector = x;
  est.lines = used;
  est.pixels = n;
  est.rms_px = n > 0 ? std::sqrt(sse / n) : 0.0;
  const double dof = std::max(1, n - used - 2);
  const Eigen::Matrix2d cov = (sse / dof) * JtJ.inverse();
  est.sigma = std::sqrt(0.5 * cov.trace());
  return est;
}

TiltRectifier::TiltRectifier(CameraGeometry geometry, const Eigen::Vector2d& tilt_vector)
    : geometry_(std::move(geometry)), tilt_(tilt_vector) {}

void TiltRectifier::apply(const cv::Mat& gray, const MirrorCircle& circle, cv::Mat& out) {
  const CameraGeometry& g = geometry_;
  if (mx_.rows != gray.rows || mx_.cols != gray.cols || key_.center != circle.center ||
      key_.r_min != circle.r_min || key_.r_max != circle.r_max) {
    key_ = circle;
    const Eigen::Matrix3d Rt = tilt_rotation_of_vector(tilt_).transpose();
    mx_.create(gray.rows, gray.cols);
    my_.create(gray.rows, gray.cols);
    const double r_lo = std::max(0.0, circle.r_min - 4.0), r_hi = circle.r_max + 4.0;
    const double cx = circle.center.x(), cy = circle.center.y();
    for (int v = 0; v < gray.rows; ++v) {
      for (int u = 0; u < gray.cols; ++u) {
        const double du = u - cx, dv = v - cy;
        const double r = std::hypot(du, dv);
        mx_(v, u) = static_cast<float>(u);
        my_(v, u) = static_cast<float>(v);
        if (r < r_lo || r > r_hi) continue;
        const double beta = g.bearing_of_image_angle(std::atan2(dv, du));
        const Eigen::Vector3d s = Rt * unit_direction(beta, g.elevation_of_radius(r));
        const double rs = g.radius_of_elevation(std::asin(std::clamp(s.z(), -1.0, 1.0)));
        const double a = g.image_angle_of_bearing(std::atan2(s.y(), s.x()));
        mx_(v, u) = static_cast<float>(cx + rs * std::cos(a));
        my_(v, u) = static_cast<float>(cy + rs * std::sin(a));
      }
    }
  }
  cv::remap(gray, out, mx_, my_, cv::INTER_CUBIC, cv::BORDER_REPLICATE);
}

double upright_bearing(const CameraGeometry& g,
                       const Eigen::Vector2d& tilt_vector,
                       double image_angle,
                       double radius) {
  const double beta = g.bearing_of_image_angle(image_angle);
  return upright_azimuth(tilt_rotation_of_vector(tilt_vector),
                         unit_direction(beta, g.elevation_of_radius(radius)));
}

}  // namespace omnivert
