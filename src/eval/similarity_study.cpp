#include "omnivert/eval/similarity_study.hpp"

#include <algorithm>
#include <cmath>

#include "omnivert/core/angles.hpp"

namespace omnivert::eval {

cv::Mat1f descriptor_distance_matrix(const DescriptorMatrix& d) {
  const int n = static_cast<int>(d.rows());
  cv::Mat1f s(n, n, 0.0f);
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const float v = (d.row(i) - d.row(j)).norm();
      s(i, j) = s(j, i) = v;
    }
  return s;
}

Distinctiveness distinctiveness(const cv::Mat1f& s, double band_deg, double ambiguous_below) {
  Distinctiveness out;
  const int n = s.rows;
  if (n < 3) return out;
  std::vector<float> all;
  all.reserve(static_cast<std::size_t>(n) * (n - 1));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (i != j) all.push_back(s(i, j));
  std::nth_element(all.begin(), all.begin() + all.size() / 2, all.end());
  out.median_distance = all[all.size() / 2];
  if (!(out.median_distance > 0)) return out;
  const double step = 360.0 / n;
  std::vector<double> ratio;
  for (int i = 0; i < n; ++i) {
    double m = std::numeric_limits<double>::infinity();
    for (int j = 0; j < n; ++j) {
      int k = std::abs(i - j);
      k = std::min(k, n - k);
      if (k * step <= band_deg) continue;
      m = std::min(m, static_cast<double>(s(i, j)));
    }
    if (std::isfinite(m)) ratio.push_back(m / out.median_distance);
  }
  std::vector<double> valley;
  for (int i = 0; i < n; ++i) {
    for (int k = 1; k <= n / 2; ++k) {
      const double v = 0.5 * (s(i, (i + k) % n) + s(i, (i - k + n) % n));
      if (v >= 0.5 * out.median_distance) {
        valley.push_back(k * step);
        break;
      }
    }
  }
  if (!valley.empty()) {
    std::nth_element(valley.begin(), valley.begin() + valley.size() / 2, valley.end());
    out.valley_deg = valley[valley.size() / 2];
  }
  if (ratio.empty()) return out;
  double sum = 0;
  int amb = 0;
  for (double r : ratio) sum += r, amb += r < ambiguous_below;
  out.gap = sum / ratio.size();
  out.ambiguous = static_cast<double>(amb) / ratio.size();
  std::nth_element(ratio.begin(), ratio.begin() + ratio.size() / 2, ratio.end());
  out.median_gap = ratio[ratio.size() / 2];
  return out;
}

SimilarityResult similarity_study(const cv::Mat& gray,
                                  const MirrorCircle& circle,
                                  const SimilarityOptions& o) {
  SimilarityResult r;
  const int n = std::max(3, o.steps);
  for (int i = 0; i < n; ++i) r.bearings.push_back(wrap_angle(i * kTwoPi / n));
  // Our descriptor at every bearing (image angle = sign * bearing, docs/theory/conventions.md).
  std::vector<double> angles;
  for (double b : r.bearings) angles.push_back(wrap_angle(o.bearing_sign * b));
  DescriptorExtractor ex(o.descriptor);
  DescriptorMatrix d;
  ex.compute_at_angles(gray, circle, angles, d);
  r.descriptor = descriptor_distance_matrix(d);
  // Patterns of width 2 r_a in the panorama (Sec. 5, Fig. 10).
  PanoramaOptions po;
  po.bearing_sign = o.bearing_sign;
  r.panorama = unwrap_panorama(gray, circle, po);
  r.pattern_columns = paper_pattern_columns(r.panorama);
  std::vector<cv::Mat1f> patterns;
  for (double b : r.bearings)
    patterns.push_back(panorama_pattern(r.panorama, b, r.pattern_columns));
  r.ssd.create(n, n);
  r.zncc.create(n, n);
  for (int i = 0; i < n; ++i) {
    r.ssd(i, i) = 0.0f;
    r.zncc(i, i) = static_cast<float>(1.0 - zncc(patterns[i], patterns[i]));
    for (int j = i + 1; j < n; ++j) {
      r.ssd(i, j) = r.ssd(j, i) = static_cast<float>(ssd_per_pixel(patterns[i], patterns[j]));
      r.zncc(i, j) = r.zncc(j, i) = static_cast<float>(1.0 - zncc(patterns[i], patterns[j]));
    }
  }
  r.descriptor_d = distinctiveness(r.descriptor, o.band_deg, o.ambiguous_below);
  // SSD and 1 - ZNCC are squared distances (of the raw and of the normalised patterns), so
  // their distinctiveness is measured on the square root, the same scale as eq. (6).
  cv::Mat1f ssd_root, zncc_root;
  cv::sqrt(cv::max(r.ssd, 0.0f), ssd_root);
  cv::sqrt(cv::max(r.zncc, 0.0f), zncc_root);
  r.ssd_d = distinctiveness(ssd_root, o.band_deg, o.ambiguous_below);
  r.zncc_d = distinctiveness(zncc_root, o.band_deg, o.ambiguous_below);
  return r;
}

}  // namespace omnivert::eval
