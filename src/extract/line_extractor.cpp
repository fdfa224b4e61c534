#include "omnivert/extract/line_extractor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "omnivert/core/angles.hpp"
#include "omnivert/image/image_mask.hpp"

namespace omnivert {

bool LineExtractorOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!(gradient_threshold > 0)) return fail("gradient_threshold must be positive");
  if (!(orientation_tolerance_deg > 0 && orientation_tolerance_deg < 45))
    return fail("orientation_tolerance_deg must be in (0, 45)");
  if (sectors < 36 || sectors > 7200) return fail("sectors must be in [36, 7200]");
  if (!(lateral_tolerance_px > 0)) return fail("lateral_tolerance_px must be positive");
  if (!(max_gap_px >= 0)) return fail("max_gap_px must not be negative");
  if (!(min_separation_deg >= 0)) return fail("min_separation_deg must not be negative");
  if (!(isolation_px >= 0 && isolation_px <= 50)) return fail("isolation_px must be in [0, 50]");
  if (peak_window < 0 || peak_window > 10) return fail("peak_window must be in [0, 10] sectors");
  if (nms_radius < 1 || nms_radius > 10) return fail("nms_radius must be in [1, 10] sectors");
  if (!(length_fraction > 0 && length_fraction <= 1))
    return fail("length_fraction must be in (0, 1]");
  if (!(adaptive_k >= 0)) return fail("adaptive_k must not be negative");
  if (top_k < 1) return fail("top_k must be at least 1");
  if (!(min_fraction >= 0 && min_fraction <= 1)) return fail("min_fraction must be in [0, 1]");
  if (!(faint_min_fraction >= 0 && faint_min_fraction <= 1))
    return fail("faint_min_fraction must be in [0, 1]");
  if (!(faint_max_fit_px > 0)) return fail("faint_max_fit_px must be positive");
  if (!(faint_min_significance >= -10 && faint_min_significance <= 1000))
    return fail("faint_min_significance must be in [-10, 1000]");
  if (!(min_significance >= -10 && min_significance <= 1000))
    return fail("min_significance must be in [-10, 1000]");
  return true;
}

LineExtractor::LineExtractor(LineExtractorOptions options) : options_(std::move(options)) {}

void LineExtractor::set_mask(const cv::Mat& usable) {
  CV_Assert(usable.empty() || usable.type() == CV_8UC1);
  // Radius 1: the 3x3 Sobel window of eq. (1).
  sobel_usable_ = usable.empty() || mask_all_usable(usable) ? cv::Mat() : erode_mask(usable, 1);
}

void LineExtractor::build_lut(const MirrorCircle& circle) {
  lut_.clear();
  const int R = static_cast<int>(std::ceil(circle.r_max)) + 1;
  const double r0 = circle.r_min, r1 = circle.r_max;
  const double to_sector = options_.sectors / kTwoPi;
  for (int dv = -R; dv <= R; ++dv) {
    for (int du = -R; du <= R; ++du) {
      const double r = std::hypot(du, dv);
      if (r < r0 || r > r1 || r < 1.0) continue;
      LutEntry e;
      e.du = du;
      e.dv = dv;
      e.ux = static_cast<float>(du / r);
      e.uy = static_cast<float>(dv / r);
      e.inv_r = static_cast<float>(1.0 / r);
      // Built once per annulus: the only atan2 of the edge stage.
      e.sector = static_cast<float>(wrap_positive(std::atan2(dv, du)) * to_sector);
      lut_.push_back(e);
    }
  }
  lut_r_min_ = r0;
  lut_r_max_ = r1;
  build_row_spans();
}

namespace {
// Direction of the principal axis of a scatter about the centre (the least-squares line
// through it), on the side of `near_a`.
double principal_angle(double sxx, double sxy, double syy, double near_a) {
  double b = 0.5 * std::atan2(2 * sxy, sxx - syy);
  if (std::cos(b - near_a) < 0) b += kPi;
  return b;
}

// log10 of the Chernoff bound of the binomial tail, P[B(n, p) >= k] <= exp(-n KL(k/n || p))
// (exact when k = n); 0 when k/n <= p.
double log10_binomial_tail(int k, int n, double p) {
  const double r = static_cast<double>(k) / n;
  if (r <= p) return 0.0;
  double kl = r * std::log(r / p);
  if (r < 1) kl += (1 - r) * std::log((1 - r) / (1 - p));
  return -n * kl / std::log(10.0);
}

// Significance of a line (docs/theory/extraction.md#significance): -log10 of the smallest
// NFA = 10^log10_tests * P[B(n, p) >= k] over the intervals of radii from the start of one
// run of consecutive hit radii to the end of a later one (the best interval always has such
// ends). `radii`: the support pixels' distances from the centre, sorted.
double line_significance(const std::vector<float>& radii, double p, double log10_tests) {
  // Runs of consecutive integer radii holding a support pixel: start, end, hits before.
  struct Run {
    int start, end, before;
  };
  // Reused across calls, as the extractor's own buffers are: no allocation per frame.
  thread_local std::vector<Run> runs;
  runs.clear();
  int hits = 0, last = std::numeric_limits<int>::min();
  for (float r : radii) {
    const int q = static_cast<int>(std::floor(r));
    if (q == last) continue;
    if (q == last + 1)
      runs.back().end = q;
    else
      runs.push_back({q, q, hits});
    ++hits;
    last = q;
  }
  double best = 0.0;
  for (std::size_t a = 0; a < runs.size(); ++a) {
    for (std::size_t b = a; b < runs.size(); ++b) {
      const int n = runs[b].end - runs[a].start + 1;
      const int k = (b + 1 < runs.size() ? runs[b + 1].before : hits) - runs[a].before;
      best = std::min(best, log10_binomial_tail(k, n, p));
    }
  }
  return -(log10_tests + best);
}
}  // namespace

template <typename F>
void LineExtractor::visit_pixels(
    int k, int pol, int span, double a, double cx, double cy, F&& f) const {
  const int N = options_.sectors;
  const double ca = std::cos(a), sa = std::sin(a);
  for (int j = -span; j <= span; ++j) {
    const int b = 2 * ((k + j + N) % N) + pol;
    for (int q = bucket_start_[b]; q < bucket_start_[b + 1]; ++q) {
      const EdgePoint& p = edges_[bucket_items_[q]];
      const double rx = p.x - cx, ry = p.y - cy;
      const double fwd = rx * ca + ry * sa;
      if (fwd <= 0) continue;
      f(rx, ry, fwd, -rx * sa + ry * ca, static_cast<double>(p.weight));
    }
  }
}

double LineExtractor::fit_angle(int k,
                                int pol,
                                double a,
                                double cx,
                                double cy,
                                const std::vector<double>* avoid,
                                double avoid_px,
                                double* fit_rms,
                                std::vector<float>* radii) const {
  const double tol = options_.lateral_tolerance_px;
  // Pixels kept from the full fit, as a fraction of its weight, below which the isolated fit
  // is not trusted (the line is close to another over most of its length).
  constexpr double kMinIsolatedWeight = 0.2;
  double full_weight = 0;
  bool ok = false;
  for (int iter = 0; iter < 4; ++iter) {
    double sxx = 0, sxy = 0, syy = 0, sl2 = 0, sw = 0, sw_all = 0;
    if (radii) radii->clear();
    // Left out by the radius alone (inside r_clear some line of `avoid` is nearer than
    // avoid_px to this one), not by the pixel's own distance from the other line: that would
    // drop the pixels on the near side first and push the fit away from the neighbour.
    double r_clear = 0;
    if (avoid)
      for (double b : *avoid) r_clear = std::max(r_clear, avoid_px / std::abs(std::sin(b - a)));
    visit_pixels(k, pol, 3, a, cx, cy, [&](double rx, double ry, double fwd, double lat, double w) {
      if (std::abs(lat) > tol) return;
      sw_all += w;
      if (fwd < r_clear) return;
      sxx += w * rx * rx, sxy += w * rx * ry, syy += w * ry * ry;
      sl2 += w * lat * lat, sw += w;
      if (radii) radii->push_back(static_cast<float>(fwd));
    });
    if (iter == 0) full_weight = sw_all;
    if (sw <= 0 || (avoid && sw < kMinIsolatedWeight * full_weight)) {
      ok = false;
      break;
    }
    ok = true;
    if (fit_rms) *fit_rms = std::sqrt(sl2 / sw);
    // Principal direction of the scatter about the centre (least-squares line through it).
    const double a_new = principal_angle(sxx, sxy, syy, a);
    const double change = std::abs(angle_diff(a_new, a));
    a = a_new;
    if (change < 1e-7) break;
  }
  if (avoid && !ok) return std::numeric_limits<double>::quiet_NaN();
  return a;
}

void LineExtractor::hidden_neighbours(int k,
                                      int pol,
                                      double a,
                                      double length,
                                      double cx,
                                      double cy,
                                      std::vector<double>* near) const {
  const double tol = options_.lateral_tolerance_px;
  // Pixels between the support's band (tol) and this far from the line, on each side.
  constexpr double kBand = 4.0;
  // A side's pixels make a line when they cover this fraction of the line's length and lie
  // this close (RMS, px) to the radial line fitted through them.
  constexpr double kMinCover = 0.3, kMaxRms = 0.6;
  double sxx[2] = {0, 0}, sxy[2] = {0, 0}, syy[2] = {0, 0}, sw[2] = {0, 0};
  int count[2] = {0, 0};
  // Sectors either side of the peak: the band's width at the inner radius of the simulator's
  // and the real images' annuli (60 px: 3.8 degrees) and the support's 3 sectors.
  constexpr int span = 8;
  visit_pixels(k, pol, span, a, cx, cy, [&](double rx, double ry, double, double lat, double w) {
    if (std::abs(lat) <= tol || std::abs(lat) > kBand) return;
    const int side = lat > 0;
    sxx[side] += w * rx * rx, sxy[side] += w * rx * ry, syy[side] += w * ry * ry;
    sw[side] += w;
    ++count[side];
  });
  for (int side = 0; side < 2; ++side) {
    if (count[side] < std::max(10.0, kMinCover * length)) continue;
    const double b = principal_angle(sxx[side], sxy[side], syy[side], a);
    // Weighted RMS distance of the side's pixels from the radial line at b: the smaller
    // eigenvalue of the scatter over the weight.
    const double tr = sxx[side] + syy[side];
    const double det = sxx[side] * syy[side] - sxy[side] * sxy[side];
    const double small = 0.5 * tr - std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
    if (!(small / sw[side] <= kMaxRms * kMaxRms)) continue;
    bool known = false;
    for (double n : *near) known = known || std::abs(angle_diff(n, b)) < deg2rad(0.2);
    if (!known) near->push_back(b);
  }
}

void LineExtractor::extract(const cv::Mat& gray,
                            const MirrorCircle& circle,
                            std::vector<VerticalLine>& out) {
  CV_Assert(gray.type() == CV_8UC1 && gray.isContinuous());
  out.clear();
  edges_.clear();
  if (!(circle.r_max > circle.r_min)) return;
  if (circle.r_min != lut_r_min_ || circle.r_max != lut_r_max_) build_lut(circle);
  if (mag_.rows != gray.rows || mag_.cols != gray.cols) {
    mag_ = cv::Mat::zeros(gray.rows, gray.cols, CV_32F);
  }
  const int cxi = static_cast<int>(std::lround(circle.center.x()));
  const int cyi = static_cast<int>(std::lround(circle.center.y()));
  const float fx = static_cast<float>(circle.center.x() - cxi);
  const float fy = static_cast<float>(circle.center.y() - cyi);
  edge_pass(gray, cxi, cyi);
  vote_sectors(cxi, cyi, fx, fy);
  bucket_edges();
  suppress_non_maxima(circle);
  refit_crowded_lines(circle);
  threshold_lines(circle, out);
  const double annulus = circle.r_max - circle.r_min;
  for (VerticalLine& l : out) l.annulus_fraction = l.edge_pixels / annulus;
}

void LineExtractor::vote_sectors(int cxi, int cyi, float fx, float fy) {
  // Step 3: thinning along the gradient, sub-pixel position, soft sector votes.
  const int W = mag_.cols;
  float* mag = mag_.ptr<float>();
  const int N = options_.sectors;
  const float to_sector = static_cast<float>(N / kTwoPi);
  for (auto& h : hist_) h.assign(N, 0.0f);
  for (const Candidate& c : cands_) {
    const int ax = std::abs(c.gx), ay = std::abs(c.gy);
    int off;
    float sx, sy;
    if (ax * 5 >= ay * 12) {  // |gx| >= 2.4 |gy|: gradient about horizontal
      off = 1, sx = 1, sy = 0;
    } else if (ay * 5 >= ax * 12) {
      off = W, sx = 0, sy = 1;
    } else if ((c.gx > 0) == (c.gy > 0)) {
      off = W + 1, sx = 1, sy = 1;
    } else {
      off = W - 1, sx = -1, sy = 1;
    }
    const float mm = mag[c.px - off], mp = mag[c.px + off];
    if (!(c.m > mm && c.m >= mp)) continue;
    const float den = mm - 2 * c.m + mp;
    const float d = den < 0 ? std::clamp(0.5f * (mm - mp) / den, -0.5f, 0.5f) : 0.0f;
    const Candidate& e = c;  // with its table entry's fields
    // Position relative to the exact centre, and the first-order angle correction of the
    // LUT's sector for the sub-pixel centre and edge offset.
    const float ox = d * sx - fx, oy = d * sy - fy;
    float sec = e.sector + (-e.uy * ox + e.ux * oy) * e.inv_r * to_sector;
    if (sec < 0) sec += N;
    if (sec >= N) sec -= N;
    const int8_t pol = (-c.gx * e.uy + c.gy * e.ux) > 0 ? 1 : -1;
    const float t = sec - 0.5f;
    const float fl = std::floor(t);
    const float w = t - fl;
    int k0 = static_cast<int>(fl);
    if (k0 < 0) k0 += N;
    const int k1 = k0 + 1 == N ? 0 : k0 + 1;
    auto& h = hist_[pol > 0 ? 1 : 0];
    h[k0] += 1.0f - w;
    h[k1] += w;
    int sec_i = static_cast<int>(sec);
    if (sec_i >= N) sec_i = N - 1;
    edges_.push_back({static_cast<float>(cxi + e.du) + d * sx,
                      static_cast<float>(cyi + e.dv) + d * sy,
                      c.m,
                      1.0f / e.inv_r,
                      static_cast<int16_t>(sec_i),
                      pol});
  }
  for (const Candidate& c : cands_) mag[c.px] = 0.0f;  // leave the buffer clean
}

void LineExtractor::bucket_edges() {
  const int N = options_.sectors;
  bucket_start_.assign(2 * N + 1, 0);
  for (const EdgePoint& p : edges_) ++bucket_start_[2 * p.sector + (p.polarity > 0) + 1];
  std::partial_sum(bucket_start_.begin(), bucket_start_.end(), bucket_start_.begin());
  bucket_items_.resize(edges_.size());
  std::vector<int32_t>& fill = bucket_fill_;
  fill.assign(bucket_start_.begin(), bucket_start_.end() - 1);
  for (int32_t i = 0; i < static_cast<int32_t>(edges_.size()); ++i) {
    const EdgePoint& p = edges_[i];
    bucket_items_[fill[2 * p.sector + (p.polarity > 0)]++] = i;
  }
}

void LineExtractor::suppress_non_maxima(const MirrorCircle& circle) {
  // Step 4: circular non-maximum suppression of the (3-sector) vote score.
  const int N = options_.sectors;
  const double L = circle.r_max - circle.r_min;
  double floor_fraction = options_.length_fraction;
  if (options_.threshold != LineThreshold::kFractionOfAnnulus) {
    floor_fraction = options_.min_fraction;
  }
  float peak_min = static_cast<float>(0.4 * floor_fraction * L);
  // Step 5's significance: a random line of polarity pol holds an edge pixel at a given radius
  // with the chance that one falls in its support band (2 lateral_tolerance wide), from the
  // frame's density of such pixels in the annulus; the tests are the sectors times the radial
  // intervals of each polarity.
  {
    const double area = std::max(1.0, static_cast<double>(lut_.size()));
    int count[2] = {0, 0};
    for (const EdgePoint& e : edges_) ++count[e.polarity > 0];
    for (int pol = 0; pol < 2; ++pol) {
      const double density = count[pol] / area;
      hit_probability_[pol] =
          std::clamp(1.0 - std::exp(-density * 2.0 * options_.lateral_tolerance_px), 1e-4, 0.5);
    }
    const double Li = std::max(1.0, std::floor(L));
    log10_tests_ = std::log10(2.0 * N * Li * (Li + 1) / 2);
  }
  if (uses_significance()) {
    // Fewer hits than this cannot be significant even in a row (votes split between two
    // sectors: half of them).
    const double p = std::max(hit_probability_[0], hit_probability_[1]);
    const double k_min = (log10_tests_ + options_.min_significance) / -std::log10(p);
    const float significant_min = static_cast<float>(std::max(2.0, 0.5 * k_min));
    const float long_min = static_cast<float>(0.4 * options_.length_fraction * L);
    peak_min = options_.threshold == LineThreshold::kSignificance
                   ? significant_min
                   : std::min(significant_min, long_min);
  }
  const double cx = circle.center.x(), cy = circle.center.y();
  const double max_gap = std::max(1.0, options_.max_gap_px);
  std::vector<float>& score = score_;
  found_.clear();
  score.resize(N);
  for (int pol = 0; pol < 2; ++pol) {
    const auto& h = hist_[pol];
    const int pw = options_.peak_window;
    for (int k = 0; k < N; ++k) {
      float sum = 0.0f;
      for (int j = -pw; j <= pw; ++j) sum += h[(k + j + N) % N];
      score[k] = sum;
    }
    for (int k = 0; k < N; ++k) {
      const float sc = score[k];
      if (sc < peak_min) continue;
      bool is_max = true;
      for (int j = 1; j <= options_.nms_radius && is_max; ++j) {
        if (score[(k + j) % N] > sc || score[(k + N - j) % N] >= sc) is_max = false;
      }
      if (!is_max) continue;
      LineCandidate lc;
      if (fit_peak(k, pol, cx, cy, max_gap, &lc)) found_.push_back(lc);
    }
  }
}

double LineExtractor::local_hit_probability(int k, int pol, double a, double cx, double cy) const {
  // Clutter is not uniform: the density is that of the edge pixels of this polarity in the
  // sectors within kLocalSpan of the peak, outside the line's own support band, over the
  // annulus area of those sectors; the frame's density is the floor.
  constexpr int kLocalSpan = 10;
  const double tol = options_.lateral_tolerance_px;
  int count = 0;
  visit_pixels(k, pol, kLocalSpan, a, cx, cy, [&](double, double, double, double lat, double) {
    if (std::abs(lat) > tol) ++count;
  });
  const double area =
      std::max(1.0, static_cast<double>(lut_.size())) * (2 * kLocalSpan + 1) / options_.sectors;
  const double p = 1.0 - std::exp(-count / area * 2.0 * tol);
  return std::clamp(std::max(p, hit_probability_[pol]), 1e-4, 0.5);
}

bool LineExtractor::fit_peak(
    int k, int pol, double cx, double cy, double max_gap, LineCandidate* lc) {
  // Step 5: gather support around the peak and refine the angle (fit through the centre).
  const int N = options_.sectors;
  std::vector<float>& radii = radii_;
  double fit_rms = 0;
  const double a =
      fit_angle(k, pol, (k + 0.5) / N * kTwoPi, cx, cy, nullptr, 0.0, &fit_rms, &radii);
  if (radii.size() < 2) return false;
  std::sort(radii.begin(), radii.end());
  double covered = 1.0;
  for (std::size_t q = 1; q < radii.size(); ++q) {
    const double gap = radii[q] - radii[q - 1];
    covered += gap <= max_gap ? gap : 1.0;
  }
  lc->peak = k;
  lc->line.image_angle = wrap_angle(a);
  lc->line.bearing = lc->line.image_angle;
  lc->line.edge_pixels = static_cast<int>(std::lround(covered));
  lc->line.r_inner = radii.front();
  lc->line.r_outer = radii.back();
  lc->line.fit_rms_px = fit_rms;
  lc->line.polarity = pol ? 1 : -1;
  lc->polarity = pol;
  lc->length = covered;
  lc->line.significance =
      line_significance(radii, local_hit_probability(k, pol, a, cx, cy), log10_tests_);
  if (!uses_significance()) return true;  // threshold_lines decides
  const double L = lut_r_max_ - lut_r_min_;
  const double s = lc->line.significance;
  return s >= options_.min_significance ||
         (s >= options_.faint_min_significance && covered >= options_.faint_min_fraction * L &&
          fit_rms <= options_.faint_max_fit_px) ||
         (options_.threshold == LineThreshold::kSignificantOrLong &&
          covered >= options_.length_fraction * L);
}

void LineExtractor::refit_crowded_lines(const MirrorCircle& circle) {
  // Step 5 again for the lines that have a neighbour: each angle is refitted from its support
  // pixels at radii where every other candidate line is at least isolation_px away, so that
  // no pixel whose Sobel window or sub-pixel parabola reaches into the other edge's gradient
  // biases the angle (docs/theory/extraction.md#edges-close-to-another). The neighbours are the
  // other candidate peaks and, on each side, a line of same-polarity edge pixels just outside
  // the support that made no peak of its own (a door leaf 0.6 degree from its frame: one
  // peak, whose fit those pixels pull). A line whose neighbour is that close over most of its
  // length is marked `crowded` and keeps its full fit. The length stays the full support's.
  if (!(options_.isolation_px > 0)) return;
  const double sep = deg2rad(options_.min_separation_deg);
  const double cx = circle.center.x(), cy = circle.center.y();
  const double D = options_.isolation_px;
  // Two lines further apart than this (radians) are D pixels apart everywhere in the annulus.
  const double reach = std::asin(std::min(1.0, D / std::max(1.0, circle.r_min)));
  std::vector<double>& near = near_;
  for (LineCandidate& f : found_) {
    near.clear();
    for (const LineCandidate& g : found_) {
      const double d = std::abs(angle_diff(g.line.image_angle, f.line.image_angle));
      // A peak of the same polarity closer than min_separation is the same edge (merged
      // below), not a neighbour.
      if (&g == &f || d >= reach || (g.polarity == f.polarity && d < sep)) continue;
      near.push_back(g.line.image_angle);
    }
    hidden_neighbours(f.peak, f.polarity, f.line.image_angle, f.length, cx, cy, &near);
    if (near.empty()) continue;
    const double a = fit_angle(f.peak, f.polarity, f.line.image_angle, cx, cy, &near, D, nullptr);
    if (std::isfinite(a))
      f.line.image_angle = f.line.bearing = wrap_angle(a);
    else
      f.line.crowded = true;
  }
}

void LineExtractor::threshold_lines(const MirrorCircle& circle, std::vector<VerticalLine>& out) {
  // Histogram thresholding (Sec. 2, last step) and the preprint's alternatives.
  std::vector<LineCandidate>& found = found_;
  const double L = circle.r_max - circle.r_min;
  const double sep = deg2rad(options_.min_separation_deg);
  double thr = options_.length_fraction * L;
  if (options_.threshold == LineThreshold::kAdaptive && !found.empty()) {
    double m = 0, m2 = 0;
    for (const auto& f : found) m += f.length, m2 += f.length * f.length;
    m /= found.size();
    const double sd = std::sqrt(std::max(0.0, m2 / found.size() - m * m));
    thr = std::max(options_.min_fraction * L, m + options_.adaptive_k * sd);
  } else if (options_.threshold == LineThreshold::kTopK) {
    thr = options_.min_fraction * L;
  }
  if (uses_significance()) thr = 0;  // fit_peak kept them
  // The most significant (or longest) first, so that of two peaks of one edge it is kept;
  // with kSignificantOrLong the long ones first, so that a shorter line in a sparser
  // neighbourhood (more significant) does not take a long line's place.
  const bool by_significance = uses_significance();
  const double long_length = options_.threshold == LineThreshold::kSignificantOrLong
                                 ? options_.length_fraction * L
                                 : std::numeric_limits<double>::infinity();
  std::sort(found.begin(), found.end(), [&](const LineCandidate& x, const LineCandidate& y) {
    const bool xl = x.length >= long_length, yl = y.length >= long_length;
    if (xl != yl) return xl;
    return by_significance ? x.line.significance > y.line.significance : x.length > y.length;
  });
  for (const LineCandidate& f : found) {
    if (f.length < thr) break;
    if (options_.threshold == LineThreshold::kTopK &&
        static_cast<int>(out.size()) >= options_.top_k)
      break;
    bool dup = false;
    for (const VerticalLine& o : out)
      if (o.polarity == f.line.polarity &&
          std::abs(angle_diff(o.image_angle, f.line.image_angle)) < sep)
        dup = true;
    if (!dup) out.push_back(f.line);
  }
  std::sort(out.begin(), out.end(), [](const VerticalLine& x, const VerticalLine& y) {
    return x.image_angle < y.image_angle;
  });
}

}  // namespace omnivert
