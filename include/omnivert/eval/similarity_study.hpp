#pragma once
// Sec. 5 of the paper: similarity matrices of one image, S(i, j) = distance between the
// radial lines at bearings i and j degrees (eq. 11-13), for our descriptor (eq. 6), and for
// SSD and ZNCC of the rectangular pattern of width 2 r_a in the cylindrical panorama
// (Fig. 10). ZNCC is shown as 1 - ZNCC, so that for all three low = similar (the paper
// inverts Fig. 12 the same way).
//
// Distinctiveness, a number per matrix (ours; docs/study.md). The diagonal is 0 by
// construction, and neighbouring bearings share pixels, so for row i we look at the smallest
// distance outside a band of +-band_deg around i: m_i = min_{|i - j| > band} S(i, j), and
// divide by the median of S (a scale-free "how far is the nearest look-alike"):
//   gap        = mean_i m_i / median(S)   (larger: more distinctive)
//   ambiguous  = share of rows with m_i / median(S) < ambiguous_below (a look-alike
//                elsewhere in the image almost as close as the line itself)
//   valley     = median over rows of the smallest k (degrees) at which the mean of
//                S(i, i - k) and S(i, i + k) reaches half the median of S: the width of the
//                dark band along the diagonal (smaller: the measure localises a line better;
//                the paper's "size of the blocks along the diagonal")
// SSD and 1 - ZNCC are squared distances, so their distinctiveness is computed on their
// square roots (RMS grey-level difference; Euclidean distance of the normalised patterns).

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/describe/descriptor.hpp"
#include "omnivert/eval/panorama.hpp"

namespace omnivert::eval {

struct Distinctiveness {
  double gap = 0.0;         // mean nearest off-band distance / median distance
  double median_gap = 0.0;  // median of the same ratio over rows
  double ambiguous = 0.0;   // share of rows whose ratio is below ambiguous_below
  double median_distance = 0.0;
  double valley_deg = 0.0;  // median half-width of the diagonal valley
};

struct SimilarityOptions {
  int steps = 360;         // bearings 0, 360/steps, ... degrees (the paper: 1 degree)
  double band_deg = 10.0;  // excluded around the diagonal (shared support)
  double ambiguous_below = 0.5;
  DescriptorOptions descriptor;  // the descriptor compared
  int bearing_sign = 1;
};

struct SimilarityResult {
  std::vector<double> bearings;     // radians, the rows/columns
  cv::Mat1f descriptor, ssd, zncc;  // zncc holds 1 - ZNCC
  Distinctiveness descriptor_d, ssd_d, zncc_d;
  Panorama panorama;
  int pattern_columns = 0;
};

// Pairwise Euclidean distances (eq. 6) between the rows of a descriptor matrix.
cv::Mat1f descriptor_distance_matrix(const DescriptorMatrix& d);

Distinctiveness distinctiveness(const cv::Mat1f& s, double band_deg, double ambiguous_below);

// All three matrices for one 8-bit grey image with its mirror circle.
SimilarityResult similarity_study(const cv::Mat& gray,
                                  const MirrorCircle& circle,
                                  const SimilarityOptions& options = {});

}  // namespace omnivert::eval
