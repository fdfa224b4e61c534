// Step 2 of Sec. 2 (LineExtractor::edge_pass): Sobel gradients (eq. 1), the magnitude
// threshold and the orientation test over the annulus. The plain pass visits the lookup
// table's pixels one by one; the fast pass runs along each row of the annulus, first the
// arithmetic of a whole run in a loop without branches (vectorised by the compiler), then the
// few pixels that passed. Same operations, same order of candidates: the same bits.

#include <algorithm>
#include <cmath>

#include "omnivert/core/angles.hpp"
#include "omnivert/extract/line_extractor.hpp"

namespace omnivert {

void LineExtractor::build_row_spans() {
  spans_.clear();
  lut_ux_.resize(lut_.size());
  lut_uy_.resize(lut_.size());
  lut_inv_r_.resize(lut_.size());
  lut_sector_.resize(lut_.size());
  std::size_t longest = 0;
  for (int32_t i = 0; i < static_cast<int32_t>(lut_.size()); ++i) {
    const LutEntry& e = lut_[i];
    lut_ux_[i] = e.ux;
    lut_uy_[i] = e.uy;
    lut_inv_r_[i] = e.inv_r;
    lut_sector_[i] = e.sector;
    // The table is in row-major order: a run continues while the row is the same and the
    // column is the next one.
    if (!spans_.empty() && spans_.back().dv == e.dv && spans_.back().du0 + spans_.back().n == e.du)
      ++spans_.back().n;
    else
      spans_.push_back({e.dv, e.du, 1, i});
    longest = std::max(longest, static_cast<std::size_t>(spans_.back().n));
  }
  row_m2_.resize(longest);
  row_gx_.resize(longest);
  row_gy_.resize(longest);
  row_passed_.resize(longest);
}

void LineExtractor::edge_pass(const cv::Mat& gray, int cxi, int cyi) {
  const bool masked = !sobel_usable_.empty();
  if (masked) CV_Assert(sobel_usable_.size() == gray.size());
  if (options_.reference) {
    masked ? edge_pass_impl<true>(gray, cxi, cyi) : edge_pass_impl<false>(gray, cxi, cyi);
  } else {
    masked ? edge_rows<true>(gray, cxi, cyi) : edge_rows<false>(gray, cxi, cyi);
  }
}

template <bool kMasked>
void LineExtractor::edge_pass_impl(const cv::Mat& gray, int cxi, int cyi) {
  // Step 2: one pass over the annulus: Sobel (eq. 1), magnitude threshold, orientation test.
  const int W = gray.cols, H = gray.rows;
  const uchar* usable = kMasked ? sobel_usable_.ptr<uchar>() : nullptr;
  float* mag = mag_.ptr<float>();
  const uchar* img = gray.ptr<uchar>();
  const float t2 = static_cast<float>(options_.gradient_threshold * options_.gradient_threshold);
  const float s = static_cast<float>(std::sin(deg2rad(options_.orientation_tolerance_deg)));
  const float s2 = s * s;
  std::vector<Candidate>& cands = cands_;
  cands.clear();
  for (int32_t i = 0; i < static_cast<int32_t>(lut_.size()); ++i) {
    const LutEntry& e = lut_[i];
    const int u = cxi + e.du, v = cyi + e.dv;
    if (u < 1 || v < 1 || u >= W - 1 || v >= H - 1) continue;
    const int idx = v * W + u;
    if constexpr (kMasked) {
      if (!usable[idx]) continue;  // the Sobel window touches a masked pixel
    }
    const uchar* p = img + idx;
    const int gx = (p[-W + 1] + 2 * p[1] + p[W + 1]) - (p[-W - 1] + 2 * p[-1] + p[W - 1]);
    const int gy = (p[W - 1] + 2 * p[W] + p[W + 1]) - (p[-W - 1] + 2 * p[-W] + p[-W + 1]);
    const float m2 = static_cast<float>(gx * gx + gy * gy);
    if (m2 < t2) continue;
    const float radial = gx * e.ux + gy * e.uy;
    if (radial * radial > s2 * m2) continue;  // gradient not tangential: not a radial edge
    const float m = std::sqrt(m2);
    mag[idx] = m;
    cands.push_back({idx,
                     static_cast<int16_t>(gx),
                     static_cast<int16_t>(gy),
                     m,
                     static_cast<int16_t>(e.du),
                     static_cast<int16_t>(e.dv),
                     e.ux,
                     e.uy,
                     e.inv_r,
                     e.sector});
  }
}

namespace {
// Sobel (eq. 1), magnitude threshold and orientation test for the n pixels from column 0 of
// the rows r0 (above), r1, r2 (below); m2[i] = |g|^2 where the pixel passes, 0 where not.
template <bool kMasked>
void row_tests(const uchar* __restrict r0,
               const uchar* __restrict r1,
               const uchar* __restrict r2,
               const uchar* __restrict usable,
               const float* __restrict ux,
               const float* __restrict uy,
               int n,
               float t2,
               float s2,
               float* __restrict m2_out,
               int16_t* __restrict gx_out,
               int16_t* __restrict gy_out) {
  for (int i = 0; i < n; ++i) {
    const int gx =
        (r0[i + 1] + 2 * r1[i + 1] + r2[i + 1]) - (r0[i - 1] + 2 * r1[i - 1] + r2[i - 1]);
    const int gy = (r2[i - 1] + 2 * r2[i] + r2[i + 1]) - (r0[i - 1] + 2 * r0[i] + r0[i + 1]);
    const float m2 = static_cast<float>(gx * gx + gy * gy);
    const float radial = gx * ux[i] + gy * uy[i];
    // Strong enough, and tangential (not a radial gradient): a radial edge pixel.
    // (& rather than &&: no branch in the loop.)
    bool pass = (m2 >= t2) & (radial * radial <= s2 * m2);
    if constexpr (kMasked) pass = pass & (usable[i] != 0);
    m2_out[i] = pass ? m2 : 0.0f;
    gx_out[i] = static_cast<int16_t>(gx);
    gy_out[i] = static_cast<int16_t>(gy);
  }
}
}  // namespace

template <bool kMasked>
void LineExtractor::edge_rows(const cv::Mat& gray, int cxi, int cyi) {
  const int W = gray.cols, H = gray.rows;
  float* mag = mag_.ptr<float>();
  const uchar* img = gray.ptr<uchar>();
  const float t2 = static_cast<float>(options_.gradient_threshold * options_.gradient_threshold);
  const float s = static_cast<float>(std::sin(deg2rad(options_.orientation_tolerance_deg)));
  const float s2 = s * s;
  cands_.clear();
  for (const RowSpan& sp : spans_) {
    const int v = cyi + sp.dv;
    if (v < 1 || v >= H - 1) continue;
    // The run cut to columns 1 .. W - 2 (the Sobel window inside the image).
    int u = cxi + sp.du0, n = sp.n, l0 = sp.lut0;
    if (u < 1) {
      n -= 1 - u;
      l0 += 1 - u;
      u = 1;
    }
    n = std::min(n, W - 1 - u);
    if (n <= 0) continue;
    const int idx0 = v * W + u;
    row_tests<kMasked>(img + idx0 - W,
                       img + idx0,
                       img + idx0 + W,
                       kMasked ? sobel_usable_.ptr<uchar>() + idx0 : nullptr,
                       lut_ux_.data() + l0,
                       lut_uy_.data() + l0,
                       n,
                       t2,
                       s2,
                       row_m2_.data(),
                       row_gx_.data(),
                       row_gy_.data());
    // The passing pixels' columns, gathered without a branch per pixel (most do not pass).
    int passed = 0;
    for (int i = 0; i < n; ++i) {
      row_passed_[passed] = i;
      passed += row_m2_[i] != 0.0f;
    }
    for (int j = 0; j < passed; ++j) {
      const int i = row_passed_[j];
      const float m = std::sqrt(row_m2_[i]);
      mag[idx0 + i] = m;
      const int l = l0 + i;
      cands_.push_back({idx0 + i,
                        row_gx_[i],
                        row_gy_[i],
                        m,
                        static_cast<int16_t>(u + i - cxi),
                        static_cast<int16_t>(sp.dv),
                        lut_ux_[l],
                        lut_uy_[l],
                        lut_inv_r_[l],
                        lut_sector_[l]});
    }
  }
}

}  // namespace omnivert
