#pragma once
// Radial (vertical-line) extraction, Sec. 2 steps 2-5.
//
// Step 2: Sobel gradients, eq. (1). A pixel is an edge pixel of a radial line if its
//   gradient magnitude passes a threshold and its gradient is within +-5 degrees of the
//   tangential direction (docs/theory/extraction.md: the paper's "looks towards the centre" read
//   literally is wrong for radial edges; it is the edge direction that points at the centre).
//   The test is a dot product against the radial unit vector: no atan2 per pixel.
// Step 3: edge thinning by non-maximum suppression along the gradient, with a sub-pixel
//   position for each surviving edge pixel (parabola through three magnitudes).
// Step 4: 720 sectors of 0.5 degree; each edge pixel votes into the two nearest sectors in
//   proportion to its distance to them (so a line on a sector boundary does not split its
//   votes), separately for the two edge polarities; circular non-maximum suppression.
// Step 5: for each peak the supporting pixels (within lateral_tolerance_px of the radial
//   line) are gathered and the line's angle is refined below the sector size by a weighted
//   least-squares fit of a line through the mirror centre; its length is the radial extent
//   covered by supporting pixels (gaps up to max_gap_px bridged), and it is kept by
//   one of the criteria below (the default: it is significant, its number of false alarms,
//   a contrario, below 10^-35, or long, the paper's >= 50% of R_max - R_min).
//
// Speed: all per-pixel geometry (radial unit vector, sector coordinate, neighbour offsets)
// comes from a lookup table built once per annulus (r_min, r_max) relative to the rounded
// centre; the sub-pixel part of the centre is corrected to first order. Buffers are reused
// across frames: no allocation per frame once warmed up.

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/core/mirror_circle.hpp"
#include "omnivert/core/vertical_line.hpp"

namespace omnivert {

enum class LineThreshold {
  // The default: kSignificance or kFractionOfAnnulus, whichever keeps the line. The
  // significant lines are the prominent edges of real rooms whose furniture hides the lower
  // part of the walls; the long ones are kept even where many edges around them make them
  // less significant (a line-rich hall).
  kSignificantOrLong,
  // A contrario (docs/theory/extraction.md#significance): NFA = n_tests * P[B(n, p) >= k] <=
  // 10^-min_significance, k of the n radii between two support pixels holding one, p the
  // chance that a radius of a random line holds an edge pixel of this polarity (the image's
  // density of such pixels in the annulus times the support band's width 2 lateral_tolerance).
  kSignificance,
  kFractionOfAnnulus,  // Sec. 2: edge_pixels >= length_fraction * (R_max - R_min)
  kAdaptive,           // preprint: edge_pixels >= mean + adaptive_k * stddev of candidates
  kTopK,               // the top_k longest candidates (still >= min_fraction)
};

struct LineExtractorOptions {
  // Sobel magnitude threshold for an edge pixel (a sharp step of h grey levels gives 4h).
  double gradient_threshold = 30.0;
  // Tolerance of the orientation test, degrees (Sec. 2: +-5 degrees).
  double orientation_tolerance_deg = 5.0;
  // Number of sectors (Sec. 2: 720, i.e. 0.5 degree).
  int sectors = 720;
  // A supporting pixel lies within this lateral distance of the radial line (pixels).
  double lateral_tolerance_px = 1.0;
  // Gaps between supporting pixels up to this many pixels count as covered: noise and
  // texture break real edges into runs, and the length criterion is about the line's extent.
  double max_gap_px = 4.0;
  // Two lines of the same polarity closer than this are one line (degrees).
  double min_separation_deg = 0.75;
  // A line with another candidate line nearby has its angle refitted from the support pixels
  // at least this far (pixels) from every other candidate: nearer, the 3x3 Sobel window and
  // the 3-pixel sub-pixel parabola reach into the other edge's gradient, which pushes the two
  // edges of a thin bar apart (drawn bars 1 degree wide: each edge 0.015 degree outwards;
  // docs/theory/extraction.md#edges-close-to-another). Kept only when at least a fifth of the
  // support's weight is that far; otherwise the line is marked crowded (VerticalLine). 0: off.
  double isolation_px = 3.0;
  // Step 4's peak score sums the votes of 2 * peak_window + 1 sectors, and a peak must beat
  // the scores of the nms_radius sectors on each side. The defaults (0 and 1: the votes of one
  // sector, peaks at least 2 sectors = 1 degree apart) resolve two edges 1 degree apart, which
  // a door frame and its leaf often are; with 1 and 2 (a 1.5-degree score, peaks 1.5 degrees
  // apart) extraction finds one of the two in each frame, whichever is stronger, and trackers
  // link them (docs/theory/extraction.md#sector-votes-and-peaks).
  int peak_window = 0;
  int nms_radius = 1;

  // The default keeps the significant lines and the long ones
  // (docs/theory/extraction.md#significance): in real rooms the paper's 50 % rule alone keeps
  // almost none, furniture hiding the lower part of most walls. The calibration uses the
  // long ones when there are enough (pipeline::DatasetRunOptions).
  LineThreshold threshold = LineThreshold::kSignificantOrLong;
  double min_significance = 35.0;  // kSignificance(OrLong): -log10 of the largest NFA kept
  double length_fraction = 0.5;    // kFractionOfAnnulus, kSignificantOrLong (the paper's 50%)
  double adaptive_k = 3.0;         // kAdaptive
  int top_k = 20;                  // kTopK
  double min_fraction = 0.2;       // floor for kAdaptive and kTopK
  // kSignificance(OrLong): a line less significant than min_significance is still kept when
  // it is at least faint_min_significance and covers faint_min_fraction of the annulus: the
  // faint long edges of a room (a wall corner between like walls), whose short fragments
  // would be clutter (docs/validation.md#faint-lines). faint_min_significance >=
  // min_significance: no faint lines.
  double faint_min_significance = 35.0;
  double faint_min_fraction = 0.2;
  // ... and whose support pixels lie within this RMS of its radial line (px): oblique texture
  // edges that pass the orientation test over part of the annulus fit a radial line worse.
  double faint_max_fit_px = 0.45;

  // Step 2 pixel by pixel through the lookup table instead of the fast path, which runs along
  // each row of the annulus in a loop the compiler vectorises. Both give the same edges and
  // lines to the bit (test LineExtractor.FastEdgePassEqualsThePlainReference).
  bool reference = false;

  bool IsValid(std::string* why) const;
};

class LineExtractor {
 public:
  explicit LineExtractor(LineExtractorOptions options = {});

  // Extracts the radial lines of an 8-bit grey image whose mirror circle is known. Lines are
  // returned sorted by image angle, with bearing = image_angle (the caller applies the
  // camera's bearing_sign). `out` is cleared first.
  void extract(const cv::Mat& gray, const MirrorCircle& circle, std::vector<VerticalLine>& out);

  const LineExtractorOptions& options() const { return options_; }

  // Image mask (image_mask.hpp: CV_8UC1, non-zero = usable) for the following calls of
  // extract, whose images must have its size. Step 2 skips every pixel whose 3x3 Sobel window
  // touches a masked pixel (the usable area eroded by one pixel), so masked pixels cast no
  // votes and the mask's own border makes no edge. An empty or all-usable mask: no mask (the
  // unmasked pass, bit-identical results).
  void set_mask(const cv::Mat& usable);
  bool has_mask() const { return !sobel_usable_.empty(); }

  // Edge pixels of the last call (after thinning), for drawing and tests: sub-pixel
  // position in the image.
  struct EdgePoint {
    float x, y;      // image position (sub-pixel)
    float weight;    // gradient magnitude
    float radius;    // distance from the centre
    int16_t sector;  // nearest sector
    int8_t polarity;
  };
  const std::vector<EdgePoint>& last_edge_points() const { return edges_; }

 private:
  struct LutEntry {
    int32_t du, dv;  // offset from the rounded centre
    float ux, uy;    // radial unit vector
    float inv_r;     // 1 / radius
    float sector;    // continuous sector coordinate of the pixel, in [0, sectors)
  };
  void build_lut(const MirrorCircle& circle);
  // The lookup table's runs of consecutive pixels along a row, and its radial unit vectors as
  // two arrays (the fast edge pass).
  void build_row_spans();
  struct RowSpan {
    int32_t dv, du0, n, lut0;  // row offset, first column offset, length, first table entry
  };
  std::vector<RowSpan> spans_;
  std::vector<float> lut_ux_, lut_uy_, lut_inv_r_, lut_sector_;
  std::vector<float> row_m2_;
  std::vector<int16_t> row_gx_, row_gy_;
  std::vector<int32_t> row_passed_;
  bool uses_significance() const {
    return options_.threshold == LineThreshold::kSignificance ||
           options_.threshold == LineThreshold::kSignificantOrLong;
  }
  // Step 5's fit: the angle of the radial line through the centre (cx, cy) fitted to the
  // support pixels of polarity `pol` near sector k, starting at angle a. With `avoid`, the
  // pixels at radii where any of those lines (angles) is nearer than avoid_px to this one
  // are left out, and NaN is returned when less than a fifth of the support's weight is left.
  // `radii` receives the distances from the centre of the pixels used.
  double fit_angle(int k,
                   int pol,
                   double a,
                   double cx,
                   double cy,
                   const std::vector<double>* avoid,
                   double avoid_px,
                   double* fit_rms,
                   std::vector<float>* radii = nullptr) const;
  // Calls f(rx, ry, fwd, lat, weight) for each thinned edge pixel of polarity `pol` in the
  // sectors k - span .. k + span that lies ahead of the centre along angle a: (rx, ry) from
  // the centre (cx, cy), fwd along the radial line at a, lat across it.
  template <typename F>
  void visit_pixels(int k, int pol, int span, double a, double cx, double cy, F&& f) const;
  // Same-polarity edge pixels just outside the support of the line at angle a (peak sector
  // k), on each side, that form a radial line of their own: its angle is added to *near
  // unless a line within 0.2 degree is there already.
  void hidden_neighbours(int k,
                         int pol,
                         double a,
                         double length,
                         double cx,
                         double cy,
                         std::vector<double>* near) const;

  LineExtractorOptions options_;
  // Lookup table over the annulus, valid for (lut_r_min_, lut_r_max_).
  std::vector<LutEntry> lut_;
  double lut_r_min_ = -1, lut_r_max_ = -1;
  struct Candidate {  // a pixel that passed the magnitude and orientation tests
    int32_t px;
    int16_t gx, gy;
    float m;
    // Its lookup-table entry's fields that step 3 needs, copied here: step 3 then reads the
    // candidates in order rather than the table (several MB) at scattered places.
    int16_t du, dv;
    float ux, uy, inv_r, sector;
  };
  struct LineCandidate {
    int peak;  // sector of the vote peak
    VerticalLine line;
    int polarity;
    double length;
  };
  // Chance that a radius of a random line holds an edge pixel of polarity 0 / 1 (step 5's
  // significance), set from the edge density of the current frame.
  double hit_probability_[2] = {0, 0};
  double log10_tests_ = 0;
  // Steps of extract (Sec. 2), each on the buffers below.
  // Step 2: one pass over the annulus (rounded centre cxi, cyi): Sobel (eq. 1), magnitude
  // threshold, orientation test; fills cands_ and mag_.
  void edge_pass(const cv::Mat& gray, int cxi, int cyi);
  template <bool kMasked>
  void edge_pass_impl(const cv::Mat& gray, int cxi, int cyi);
  template <bool kMasked>
  void edge_rows(const cv::Mat& gray, int cxi, int cyi);
  // Step 3: thinning along the gradient, sub-pixel position, soft sector votes into hist_;
  // fills edges_ ((fx, fy): the centre's offset from (cxi, cyi)) and clears mag_.
  void vote_sectors(int cxi, int cyi, float fx, float fy);
  // Buckets of edge points by (sector, polarity), for gathering a line's support.
  void bucket_edges();
  // Step 4: circular non-maximum suppression of the vote score; each peak fitted (step 5)
  // into found_.
  void suppress_non_maxima(const MirrorCircle& circle);
  // Step 5: the support of the peak at sector k and its fitted line; false when too small.
  bool fit_peak(int k, int pol, double cx, double cy, double max_gap, LineCandidate* lc);
  // Step 5's chance that a radius of a random line near sector k holds an edge pixel of
  // polarity pol: from the density of such pixels around the line, at least the frame's.
  double local_hit_probability(int k, int pol, double a, double cx, double cy) const;
  // Step 5 again for the lines of found_ that have a neighbour.
  void refit_crowded_lines(const MirrorCircle& circle);
  // Histogram thresholding (Sec. 2, last step) of found_ into out, sorted by image angle.
  void threshold_lines(const MirrorCircle& circle, std::vector<VerticalLine>& out);
  // Pixels whose Sobel window is wholly usable (set_mask); empty: no mask.
  cv::Mat sobel_usable_;
  // Reused buffers (no allocation per frame once warmed up).
  cv::Mat mag_;  // float magnitude of candidates (0 elsewhere)
  std::vector<Candidate> cands_;
  std::vector<EdgePoint> edges_;
  std::vector<LineCandidate> found_;
  std::vector<float> radii_, score_;
  std::vector<double> near_;
  std::vector<int32_t> bucket_fill_;
  std::vector<float> hist_[2];
  std::vector<int32_t> bucket_start_;
  std::vector<int32_t> bucket_items_;
};

}  // namespace omnivert
