#include "omnivert/describe/descriptor.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "describe/fast_math.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/image/image_mask.hpp"

namespace omnivert {

bool DescriptorOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (bins < 4 || bins > 256) return fail("bins must be in [4, 256]");
  if (areas != 3 && areas != 5) return fail("areas must be 3 or 5");
  if (!(clip > 0 && clip <= 1)) return fail("clip must be in (0, 1]");
  if (!(sigma_fraction > 0 && sigma_fraction <= 2)) return fail("sigma_fraction must be in (0, 2]");
  if (!(log_offset > 0)) return fail("log_offset must be positive");
  return true;
}

DescriptorExtractor::DescriptorExtractor(DescriptorOptions options)
    : options_(std::move(options)) {}

void DescriptorExtractor::set_mask(const cv::Mat& usable) {
  CV_Assert(usable.empty() || usable.type() == CV_8UC1);
  usable_ = usable.empty() || mask_all_usable(usable) ? cv::Mat() : usable.clone();
}

double DescriptorExtractor::area_radius(const MirrorCircle& circle) const {
  return (circle.r_max - circle.r_min) / 6.0;  // r_a, Sec. 3.1
}

std::vector<cv::Point2d> DescriptorExtractor::area_centers(const MirrorCircle& circle,
                                                           double image_angle) const {
  const double ra = area_radius(circle);
  std::vector<cv::Point2d> c;
  const double ca = std::cos(image_angle), sa = std::sin(image_angle);
  for (int k = 0; k < options_.areas; ++k) {
    // Three touching areas at R_min + (1, 3, 5) r_a, or five at R_min + (1..5) r_a.
    const double r = circle.r_min + (options_.areas == 3 ? (2 * k + 1) : (k + 1)) * ra;
    c.emplace_back(circle.center.x() + r * ca, circle.center.y() + r * sa);
  }
  return c;
}

void DescriptorExtractor::prepare(const cv::Mat& gray, const MirrorCircle& circle) {
  const double ra = area_radius(circle);
  const double sigma = options_.sigma_fraction * ra;
  const bool blur = options_.smoothing == DescriptorSmoothing::kGaussianBlur;
  // The blurred image holds nothing finer than sigma: sample it every `step_` pixels
  // (area-average by step_, then blur with the remaining sigma), with step_ chosen so that
  // sigma_G spans at least min_samples_per_sigma samples. Same histograms as full resolution up to
  // sampling, at 1/step_^2 of the cost.
  step_ = blur ? std::clamp(static_cast<int>(sigma / options_.min_samples_per_sigma), 1, 8) : 1;
  const double reach = circle.r_max + 2;
  const int margin = blur ? static_cast<int>(std::ceil(3 * sigma)) + 2 * step_ : 2;
  cv::Rect roi(static_cast<int>(circle.center.x() - reach) - margin,
               static_cast<int>(circle.center.y() - reach) - margin,
               static_cast<int>(2 * reach) + 2 * margin + 1,
               static_cast<int>(2 * reach) + 2 * margin + 1);
  roi &= cv::Rect(0, 0, gray.cols, gray.rows);
  // Whole steps only, so that sample (i, j) covers pixels [i*step_, (i+1)*step_).
  roi.width -= roi.width % step_;
  roi.height -= roi.height % step_;
  roi_ = roi;
  const cv::Mat src = gray(roi_);
  if (blur) {
    // Sec. 3.1, read as a blur of the image with sigma_G before the gradients, in floating
    // point (a blur of ~10 px rounded back to 8 bits leaves a staircase whose gradients
    // follow the pixel grid: measured 0.31 mean descriptor change under a 17 degree
    // rotation, 0.00 at 90 degrees). With log_intensity the log comes first, so that
    // blur(log I') = const + gamma * blur(log I) exactly.
    if (log_lut_.empty() || log_lut_offset_ != options_.log_offset ||
        log_lut_log_ != options_.log_intensity) {
      log_lut_.create(1, 256, CV_32F);
      for (int i = 0; i < 256; ++i)
        log_lut_.at<float>(i) = options_.log_intensity
                                    ? static_cast<float>(std::log(options_.log_offset + i))
                                    : static_cast<float>(i);
      log_lut_offset_ = options_.log_offset;
      log_lut_log_ = options_.log_intensity;
    }
    cv::LUT(src, log_lut_, full_);
    const cv::Size samples(full_.cols / step_, full_.rows / step_);
    if (!usable_.empty()) {
      // Normalised convolution, blur(I M) / blur(M) with M = 1 - masked: the masked pixels
      // are zeroed and the masked fraction is blurred alongside. Far from the mask both are
      // exact (zero masked fraction), so the descriptors there are bit-identical.
      full_.setTo(0.0f, usable_(roi_) == 0);
      cv::Mat masked;
      cv::compare(usable_(roi_), 0, masked, cv::CMP_EQ);
      masked.convertTo(mask_f_, CV_32F, 1.0 / 255.0);
      if (step_ > 1) cv::resize(mask_f_, mask_f_, samples, 0, 0, cv::INTER_AREA);
      sample_usable_ = 1.0f - mask_f_;
    }
    if (step_ > 1) {
      cv::resize(full_, blurred_, samples, 0, 0, cv::INTER_AREA);
    } else {
      blurred_ = full_;
    }
    // The box average already blurred by a variance of (step^2 - 1)/12 px^2.
    const double rest =
        std::sqrt(std::max(0.25, sigma * sigma - (step_ * step_ - 1) / 12.0)) / step_;
    cv::GaussianBlur(blurred_, blurred_, cv::Size(), rest, 0, cv::BORDER_REPLICATE);
    if (!usable_.empty()) {
      cv::GaussianBlur(mask_f_, weight_, cv::Size(), rest, 0, cv::BORDER_REPLICATE);
      for (int v = 0; v < blurred_.rows; ++v) {
        float* b = blurred_.ptr<float>(v);
        const float* w = weight_.ptr<float>(v);
        // Where no usable pixel is near, the value stays 0 (and so does the samples' weight).
        for (int u = 0; u < blurred_.cols; ++u)
          if (w[u] > 0.0f) b[u] /= std::max(1e-6f, 1.0f - w[u]);
      }
    }
    cv::Sobel(blurred_, gx_, CV_32F, 1, 0, 3);
    cv::Sobel(blurred_, gy_, CV_32F, 0, 1, 3);
  } else {
    cv::Sobel(src, gx_, CV_32F, 1, 0, 3);
    cv::Sobel(src, gy_, CV_32F, 0, 1, 3);
    // A pixel votes only when its whole Sobel window is usable.
    if (!usable_.empty()) {
      sample_usable_ = cv::Mat::zeros(gx_.size(), CV_32F);
      sample_usable_.setTo(1.0f, erode_mask(usable_(roi_), 1));
    }
  }
  if (usable_.empty()) sample_usable_.release();
  if (!options_.reference) polar_table(circle);
}

void DescriptorExtractor::polar_table(const MirrorCircle& circle) {
  // The part of each sample's vote that does not depend on the line: |g| (times the usable
  // fraction) and atan2(gy, gx), once per frame rather than once per area that covers the
  // sample. The same float operations as describe_one_reference, so the same bits.
  // Only the annulus is computed: every area lies within r_min .. r_max of the centre (Sec. 3.1)
  // and a sample beyond half a cell of it does not vote. Samples further than `pad` outside
  // are set to zero (no vote), which is what describe_one reads there.
  mag_.create(gx_.size(), CV_32F);
  angle_.create(gx_.size(), CV_32F);
  const double st = step_, off = 0.5 * st - 0.5, pad = 2 * st + 2;
  const double cx = circle.center.x() - roi_.x - off, cy = circle.center.y() - roi_.y - off;
  const double r_out = circle.r_max + pad, r_in = circle.r_min - pad;
  const int cols = gx_.cols;
  // Sample columns whose offset from the centre's column is within +-h: [lo, hi] (clamped).
  auto span_of = [&](double h, bool outer) {
    int lo = outer ? static_cast<int>(std::floor((cx - h) / st))
                   : static_cast<int>(std::ceil((cx - h) / st));
    int hi = outer ? static_cast<int>(std::ceil((cx + h) / st))
                   : static_cast<int>(std::floor((cx + h) / st));
    return std::pair<int, int>(std::max(0, lo), std::min(cols - 1, hi));
  };
  for (int v = 0; v < gx_.rows; ++v) {
    const float* px = gx_.ptr<float>(v);
    const float* py = gy_.ptr<float>(v);
    float* m = mag_.ptr<float>(v);
    float* a = angle_.ptr<float>(v);
    std::fill(m, m + cols, 0.0f);
    std::fill(a, a + cols, 0.0f);
    const double y = v * st - cy;
    if (y * y > r_out * r_out) continue;
    const auto [lo, hi] = span_of(std::sqrt(r_out * r_out - y * y), true);
    // The hole inside r_in: [hole_lo, hole_hi] is left at zero.
    int hole_lo = hi + 1, hole_hi = hi;
    if (r_in > 0 && y * y < r_in * r_in) {
      const auto h = span_of(std::sqrt(r_in * r_in - y * y), false);
      if (h.first <= h.second) {
        hole_lo = h.first;
        hole_hi = h.second;
      }
    }
    const float* pu = sample_usable_.empty() ? nullptr : sample_usable_.ptr<float>(v);
    auto compute = [&](int u0, int u1) {
      for (int u = u0; u <= u1; ++u) {
        m[u] = std::sqrt(px[u] * px[u] + py[u] * py[u]);
        a[u] = fast_atan2_any(py[u], px[u]);
      }
      if (pu)
        for (int u = u0; u <= u1; ++u) m[u] *= pu[u];
    };
    compute(lo, std::min(hi, hole_lo - 1));
    compute(std::max(lo, hole_hi + 1), hi);
  }
}

namespace {
// One row of an area's samples, prepared for voting (describe_one): per sample its magnitude
// (zero: no vote), lower bin and weight of eq. (2), and left-side fraction (Sec. 3.2).
struct VoteRow {
  std::vector<float> m, w, left, d2;
  std::vector<int> b;
  void reserve(std::size_t n) {
    if (m.size() >= n) return;
    m.resize(n);
    w.resize(n);
    left.resize(n);
    d2.resize(n);
    b.resize(n);
  }
};

// std::clamp(x, 0, 1) by value: a select the compiler can vectorise (std::clamp returns a
// reference).
inline float clamp01(float x) { return x < 0.0f ? 0.0f : (1.0f < x ? 1.0f : x); }

// The constants of one line's areas (describe_one).
struct AreaGeometry {
  float st, inv_st, off, ra, ra2, theta, dx, dy, to_bin, cx;
  int nb;
};

// The per-sample arithmetic of describe_one_reference for samples ua .. ua + n - 1 of a row at
// ry from the area's centre, with |g| (pm) and atan2 (pa) from the table: a loop without
// branches over distinct buffers, which the compiler vectorises.
void prepare_votes(const AreaGeometry& g,
                   int ua,
                   int n,
                   float ry,
                   const float* __restrict pm,
                   const float* __restrict pa,
                   VoteRow& out) {
  const float st = g.st, inv_st = g.inv_st, off = g.off, ra = g.ra, ra2 = g.ra2;
  const float theta = g.theta, dx = g.dx, dy = g.dy, to_bin = g.to_bin, cx = g.cx;
  const int nb = g.nb;
  const float two_pi = static_cast<float>(kTwoPi);
  const float inv_two_pi = static_cast<float>(1.0 / kTwoPi);
  float* __restrict vm = out.m.data();
  float* __restrict vw = out.w.data();
  float* __restrict vleft = out.left.data();
  float* __restrict vd2 = out.d2.data();
  int* __restrict vb = out.b.data();
  for (int i = 0; i < n; ++i) {
    const float rx = static_cast<float>(ua + i) * st + off - cx;
    const float d2 = rx * rx + ry * ry;
    // A sample's share of the area and of each side: linear ramps one cell wide.
    const float inside = clamp01((ra - std::sqrt(d2)) * inv_st + 0.5f);
    // Outside the disc: no vote (a product, not a select, so that the load of pm[i] stays
    // unconditional; m * 0 = +0 as m >= 0).
    vm[i] = pm[i] * inside * (d2 > ra2 ? 0.0f : 1.0f);
    vd2[i] = d2;
    // Sec. 3.1: orientation relative to the line, wrapped to [0, 2 pi) without floor().
    float phi = pa[i] - theta;
    const float q = phi * inv_two_pi;
    float fq = static_cast<float>(static_cast<int>(q));
    fq = fq > q ? fq - 1.0f : fq;
    phi -= two_pi * fq;
    const float t = phi * to_bin;
    const int b = static_cast<int>(t);
    vw[i] = t - static_cast<float>(b);
    vb[i] = b >= nb ? b - nb : b;
    vleft[i] = clamp01((dx * ry - dy * rx) * inv_st + 0.5f);
  }
}
}  // namespace

void DescriptorExtractor::describe_one(const MirrorCircle& circle,
                                       double image_angle,
                                       float* row) const {
  // describe_one_reference in two passes per row of an area: the per-sample arithmetic as a
  // loop without branches (the compiler vectorises it), with |g| and the orientation from
  // polar_table(), then the votes. Each row is cut to the samples its disc can reach. The
  // same float operations on every vote as the reference, so the same bits.
  const int nb = options_.bins;
  const double ra = area_radius(circle);
  const double sigma = options_.sigma_fraction * ra;
  const float inv_2s2 = static_cast<float>(1.0 / (2 * sigma * sigma));
  const bool weighted = options_.smoothing == DescriptorSmoothing::kGaussianWeight;
  const float theta = static_cast<float>(image_angle);
  const float dx = std::cos(theta), dy = std::sin(theta);
  const float st = static_cast<float>(step_);
  const float inv_st = 1.0f / st;
  const float ra_out = static_cast<float>(ra) + 0.5f * st;
  const float ra2 = ra_out * ra_out;
  const float off = 0.5f * st - 0.5f;
  AreaGeometry g{st,
                 inv_st,
                 off,
                 static_cast<float>(ra),
                 ra2,
                 theta,
                 dx,
                 dy,
                 static_cast<float>(nb / kTwoPi),
                 0.0f,
                 nb};
  thread_local VoteRow vr;
  vr.reserve(static_cast<std::size_t>(gx_.cols));
  const float* const vm = vr.m.data();
  const float* const vw = vr.w.data();
  const float* const vleft = vr.left.data();
  const float* const vd2 = vr.d2.data();
  const int* const vb = vr.b.data();
  std::fill(row, row + options_.size(), 0.0f);
  const auto centers = area_centers(circle, image_angle);
  for (int k = 0; k < options_.areas; ++k) {
    float* hl = row + (2 * k) * nb;
    float* hr = row + (2 * k + 1) * nb;
    const float cx = static_cast<float>(centers[k].x - roi_.x);
    const float cy = static_cast<float>(centers[k].y - roi_.y);
    g.cx = cx;
    const int u0 = std::max(1, static_cast<int>(std::floor((cx - ra - off) / st)));
    const int u1 = std::min(gx_.cols - 2, static_cast<int>(std::ceil((cx + ra - off) / st)));
    const int v0 = std::max(1, static_cast<int>(std::floor((cy - ra - off) / st)));
    const int v1 = std::min(gx_.rows - 2, static_cast<int>(std::ceil((cy + ra - off) / st)));
    for (int v = v0; v <= v1; ++v) {
      const float ry = v * st + off - cy;
      // rx^2 + ry^2 >= ry^2 in floating point too: the whole row is outside the disc.
      if (ry * ry > ra2) continue;
      // Samples further than the chord's half-length plus a cell fail the disc test anyway.
      const float half = std::sqrt(ra2 - ry * ry) + st;
      const int ua = std::max(u0, static_cast<int>(std::floor((cx - half - off) * inv_st)));
      const int ub = std::min(u1, static_cast<int>(std::ceil((cx + half - off) * inv_st)));
      const int n = ub - ua + 1;
      if (n <= 0) continue;
      prepare_votes(g, ua, n, ry, mag_.ptr<float>(v) + ua, angle_.ptr<float>(v) + ua, vr);
      for (int i = 0; i < n; ++i) {
        float m = vm[i];
        if (m == 0.0f) continue;
        if (weighted) m *= std::exp(-vd2[i] * inv_2s2);
        // Eq. (2): m (1 - w) to the lower bin, m w to the upper, circularly.
        const int b = vb[i];
        const int b1 = b + 1 == nb ? 0 : b + 1;
        const float w = vw[i];
        const float ml = m * vleft[i], mr = m - ml;
        hl[b] += ml * (1.0f - w);
        hl[b1] += ml * w;
        hr[b] += mr * (1.0f - w);
        hr[b1] += mr * w;
      }
    }
  }
  normalize(row);
}

void DescriptorExtractor::describe_one_reference(const MirrorCircle& circle,
                                                 double image_angle,
                                                 float* row) const {
  const int nb = options_.bins;
  const double ra = area_radius(circle);
  const double sigma = options_.sigma_fraction * ra;
  const float inv_2s2 = static_cast<float>(1.0 / (2 * sigma * sigma));
  const bool weighted = options_.smoothing == DescriptorSmoothing::kGaussianWeight;
  const float theta = static_cast<float>(image_angle);
  const float dx = std::cos(theta), dy = std::sin(theta);
  const float to_bin = static_cast<float>(nb / kTwoPi);
  const float st = static_cast<float>(step_);
  const float inv_st = 1.0f / st;
  const float ra_out = static_cast<float>(ra) + 0.5f * st;  // samples beyond cannot touch the area
  const float ra2 = ra_out * ra_out;
  // Image position of gradient sample (i, j): roi origin + (i + 0.5) step - 0.5.
  const float off = 0.5f * st - 0.5f;
  std::fill(row, row + options_.size(), 0.0f);
  const auto centers = area_centers(circle, image_angle);
  for (int k = 0; k < options_.areas; ++k) {
    float* hl = row + (2 * k) * nb;  // H_kL: side of increasing image angle
    float* hr = row + (2 * k + 1) * nb;
    const float cx = static_cast<float>(centers[k].x - roi_.x);
    const float cy = static_cast<float>(centers[k].y - roi_.y);
    const int u0 = std::max(1, static_cast<int>(std::floor((cx - ra - off) / st)));
    const int u1 = std::min(gx_.cols - 2, static_cast<int>(std::ceil((cx + ra - off) / st)));
    const int v0 = std::max(1, static_cast<int>(std::floor((cy - ra - off) / st)));
    const int v1 = std::min(gx_.rows - 2, static_cast<int>(std::ceil((cy + ra - off) / st)));
    for (int v = v0; v <= v1; ++v) {
      const float* px = gx_.ptr<float>(v);
      const float* py = gy_.ptr<float>(v);
      const float* pu = sample_usable_.empty() ? nullptr : sample_usable_.ptr<float>(v);
      const float ry = v * st + off - cy;
      for (int u = u0; u <= u1; ++u) {
        const float rx = u * st + off - cx;
        const float d2 = rx * rx + ry * ry;
        if (d2 > ra2) continue;
        const float gx = px[u], gy = py[u];
        float m = std::sqrt(gx * gx + gy * gy);
        if (pu) m *= pu[u];  // masked pixels add nothing
        if (m == 0.0f) continue;
        // A sample stands for a step x step cell: it belongs to the area, and to each side
        // of the line, by the fraction of the cell inside (linear ramps one cell wide), so
        // that the histograms do not depend on how the sample grid falls on the line.
        const float inside =
            std::clamp((static_cast<float>(ra) - std::sqrt(d2)) * inv_st + 0.5f, 0.0f, 1.0f);
        m *= inside;
        if (weighted) m *= std::exp(-d2 * inv_2s2);
        // Sec. 3.1: orientation relative to the line, in [0, 2 pi).
        float phi = fast_atan2(gy, gx) - theta;
        phi -= static_cast<float>(kTwoPi) * std::floor(phi * static_cast<float>(1.0 / kTwoPi));
        // Eq. (2): m (1 - w) to the lower bin b, m w to the upper, circularly.
        const float t = phi * to_bin;
        int b = static_cast<int>(t);
        const float w = t - b;
        if (b >= nb) b -= nb;
        const int b1 = b + 1 == nb ? 0 : b + 1;
        // Sec. 3.2: side of the line (cross product), split over one cell across it.
        const float left = std::clamp((dx * ry - dy * rx) * inv_st + 0.5f, 0.0f, 1.0f);
        const float ml = m * left, mr = m - ml;
        hl[b] += ml * (1.0f - w);
        hl[b1] += ml * w;
        hr[b] += mr * (1.0f - w);
        hr[b1] += mr * w;
      }
    }
  }
  normalize(row);
}

void DescriptorExtractor::normalize(float* row) const {
  // Sec. 3.3: unit length, clip at `clip`, renormalise, for each histogram unit.
  const int unit = options_.normalization == DescriptorNormalization::kPerPair ? 2 * options_.bins
                                                                               : options_.bins;
  const float clip = static_cast<float>(options_.clip);
  for (int s = 0; s < options_.size(); s += unit) {
    float* h = row + s;
    for (int pass = 0; pass < 2; ++pass) {
      double n2 = 0;
      for (int i = 0; i < unit; ++i) n2 += double(h[i]) * h[i];
      if (n2 <= 0) break;  // empty (flat) area: leave zeros, never NaN
      const float inv = static_cast<float>(1.0 / std::sqrt(n2));
      for (int i = 0; i < unit; ++i) {
        h[i] *= inv;
        if (pass == 0 && h[i] > clip) h[i] = clip;
      }
    }
  }
}

void DescriptorExtractor::compute(const cv::Mat& gray,
                                  const MirrorCircle& circle,
                                  std::span<const VerticalLine> lines,
                                  DescriptorMatrix& out) {
  CV_Assert(gray.type() == CV_8UC1);
  out.resize(static_cast<Eigen::Index>(lines.size()), options_.size());
  if (lines.empty()) return;
  prepare(gray, circle);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    float* row = out.row(static_cast<Eigen::Index>(i)).data();
    if (options_.reference)
      describe_one_reference(circle, lines[i].image_angle, row);
    else
      describe_one(circle, lines[i].image_angle, row);
  }
}

void DescriptorExtractor::compute_at_angles(const cv::Mat& gray,
                                            const MirrorCircle& circle,
                                            std::span<const double> image_angles,
                                            DescriptorMatrix& out) {
  CV_Assert(gray.type() == CV_8UC1);
  out.resize(static_cast<Eigen::Index>(image_angles.size()), options_.size());
  if (image_angles.empty()) return;
  prepare(gray, circle);
  for (std::size_t i = 0; i < image_angles.size(); ++i) {
    float* row = out.row(static_cast<Eigen::Index>(i)).data();
    if (options_.reference)
      describe_one_reference(circle, image_angles[i], row);
    else
      describe_one(circle, image_angles[i], row);
  }
}

}  // namespace omnivert
