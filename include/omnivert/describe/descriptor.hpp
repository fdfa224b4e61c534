#pragma once
// The rotation-invariant descriptor of a radial line (Sec. 3).
//
// Three circular areas of radius r_a = (R_max - R_min)/6 sit on the line at radii
// R_min + r_a, R_min + 3 r_a, R_min + 5 r_a (they touch and cover the annulus;
// docs/theory/descriptor.md). In each area the gradient orientation of every pixel is taken
// relative to the line's image angle theta (Sec. 3.1: rotation invariance), and the pixel votes,
// with its gradient magnitude, into the orientation histogram of its side of the line (Sec. 3.2:
// left/right halves), split between the two nearest of N_b bins (eq. 2, soft binning). The
// histograms are stacked, eq. (3)-(4):
//   H = [H_1L, H_1R, H_2L, H_2R, H_3L, H_3R],  N = 3 areas x 2 halves x 32 bins = 192 (eq. 5).
// "L" is the half on the side of increasing image angle, "R" the other.
// Illumination (Sec. 3.3): each histogram unit is scaled to unit length, every bin clipped
// at 0.1, and the unit renormalised.
//
// Two readings of the paper are options (docs/theory/descriptor.md):
// - smoothing: "smooth each area with a Gaussian window, sigma_G = r_a/3" as a Gaussian
//   weight on each vote by its distance from the area centre (kGaussianWeight) or as a
//   Gaussian blur of the image before the gradients (kGaussianBlur);
// - normalisation unit: the pair H_i = [H_iL, H_iR] of eq. (3) (kPerPair, three 64-vectors)
//   or each half (kPerHalf, six 32-vectors).
// The defaults were chosen by measuring nearest-neighbour matching on rotated and re-lit
// images (docs/theory/descriptor.md#measurements gives the numbers).

#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/core/mirror_circle.hpp"
#include "omnivert/core/vertical_line.hpp"
#include "omnivert/describe/frame_features.hpp"

namespace omnivert {

enum class DescriptorSmoothing { kGaussianWeight, kGaussianBlur };
enum class DescriptorNormalization { kPerPair, kPerHalf };

struct DescriptorOptions {
  int bins = 32;  // N_b (Sec. 3.2); 8 and 16 for the study of Sec. 6.0.4
  int areas = 3;  // 3 touching areas, or 5 overlapping by 50% (Sec. 6.0.4)
  DescriptorSmoothing smoothing = DescriptorSmoothing::kGaussianBlur;
  DescriptorNormalization normalization = DescriptorNormalization::kPerPair;
  double clip = 0.1;                  // Sec. 3.3
  double sigma_fraction = 1.0 / 3.0;  // sigma_G = sigma_fraction * r_a (Sec. 3.1)
  // Gradients of log(log_offset + I) instead of I (an extension of Sec. 3.3): a gain g and gamma y
  // map log I to const + y log I, so after the blur and unit normalisation the descriptor is
  // unchanged by both (up to noise and saturation). Applies to the blur reading.
  bool log_intensity = true;
  // Offset in log(offset + I): keeps near-black pixels (noise, interpolation) from dominating.
  double log_offset = 2.0;

  // Blur reading: gradients are sampled every floor(sigma_G / this) pixels (>= 1); the
  // blurred image holds nothing finer. A large value forces full resolution. At 4, a camera
  // whose annulus is 120-240 px wide (sigma_G 6.7-13.3 px with 3 areas) samples every 1-3 px.
  double min_samples_per_sigma = 4.0;

  // The plain per-sample computation (gradient magnitude, orientation and area distance for
  // every sample of every area) instead of the fast path, which takes magnitude and
  // orientation once per frame from a table. The two give the same descriptors to the bit
  // (test Descriptor.FastPathEqualsThePlainReference); the plain one is kept to check it.
  bool reference = false;

  bool IsValid(std::string* why) const;
  // Descriptor length: areas x 2 halves x bins.
  int size() const { return areas * 2 * bins; }
};

class DescriptorExtractor {
 public:
  explicit DescriptorExtractor(DescriptorOptions options = {});

  // One row of `out` per line (resized to lines.size() x options().size()).
  void compute(const cv::Mat& gray,
               const MirrorCircle& circle,
               std::span<const VerticalLine> lines,
               DescriptorMatrix& out);

  // The same at arbitrary image angles (radians): for similarity matrices (Sec. 5).
  void compute_at_angles(const cv::Mat& gray,
                         const MirrorCircle& circle,
                         std::span<const double> image_angles,
                         DescriptorMatrix& out);

  const DescriptorOptions& options() const { return options_; }

  // Image mask (image_mask.hpp: CV_8UC1, non-zero = usable) for the following calls, whose
  // images must have its size; docs/extraction.md#image-masks. Masked pixels add nothing to
  // the histograms: in the blur reading the image is blurred by normalised convolution
  // (blur(I M) / blur(M): masked pixels are filled from the usable ones around them, so the
  // mask's border makes no gradient) and each gradient sample votes with the usable fraction
  // of its cell; in the weight reading a pixel whose Sobel window touches the mask does not
  // vote. Normalisation is unchanged: a partly masked area is described by its usable pixels,
  // scaled to unit length like any other; a wholly masked unit stays zero. An empty or
  // all-usable mask: no mask (bit-identical descriptors).
  void set_mask(const cv::Mat& usable);

  // Centres (image pixels) and radius of the circular areas of a line at image angle a.
  std::vector<cv::Point2d> area_centers(const MirrorCircle& circle, double image_angle) const;
  double area_radius(const MirrorCircle& circle) const;

 private:
  void prepare(const cv::Mat& gray, const MirrorCircle& circle);
  void describe_one(const MirrorCircle& circle, double image_angle, float* row) const;
  void describe_one_reference(const MirrorCircle& circle, double image_angle, float* row) const;
  void polar_table(const MirrorCircle& circle);
  void normalize(float* row) const;

  DescriptorOptions options_;
  cv::Rect roi_;  // region of the frame the gradient images cover
  int step_ = 1;  // one gradient sample every step_ pixels (blur reading)
  cv::Mat full_, blurred_, gx_, gy_;
  cv::Mat mag_, angle_;    // fast path: per sample |g| (times its usable fraction), atan2(gy, gx)
  cv::Mat usable_;         // set_mask; empty: no mask
  cv::Mat sample_usable_;  // per gradient sample: usable fraction in [0, 1] (CV_32F); or empty
  cv::Mat mask_f_, weight_;
  cv::Mat log_lut_;  // grey level -> log(offset + I) (or I)
  double log_lut_offset_ = -1;
  bool log_lut_log_ = false;
};

}  // namespace omnivert
