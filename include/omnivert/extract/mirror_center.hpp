#pragma once
// Mirror centre and valid annulus of a catadioptric image (Sec. 2, step 1).
//
// The paper convolves the binary edge image with a ring mask of the (known) rim radius and
// takes the accumulator maximum. We do the same vote more cheaply: every edge pixel near the
// expected rim votes at the two points one rim radius away along its gradient (a ring mask
// centred on an edge pixel meets the gradient line there), the accumulator is smoothed, and
// its maximum is the coarse centre. The centre is then refined below the pixel by fitting a
// circle (least squares, outliers rejected) to rim points found with sub-pixel precision
// along rays from the coarse centre.
//
// Without a known rim radius, `estimate` finds the centre from all circular edges (their
// gradient lines meet at the centre) and then the rim radius from the radial edge profile;
// this is meant for one static image, as in the paper, and its result seeds `detect`.

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/core/mirror_circle.hpp"

namespace omnivert {

struct MirrorCenterOptions {
  // Gradient magnitude (Sobel units, 4x the grey-level step of a sharp edge) for an edge pixel.
  double edge_threshold = 40.0;
  // How far (pixels) the centre may move from its prior between frames (vibration).
  double search_radius = 15.0;
  // Number of rays used for the sub-pixel rim fit.
  int rim_rays = 360;
  // Half-length (pixels) of the radial window searched for the rim along each ray.
  double rim_window = 6.0;
  // Valid annulus derived from the rim when r_max is not given: r_max = rim - margin.
  double rim_margin_fraction = 0.03;
  // r_min (when not given) = radius of the camera's self-reflection * (1 + this).
  double inner_margin_fraction = 0.10;

  bool IsValid(std::string* why) const;
};

class MirrorCenterDetector {
 public:
  explicit MirrorCenterDetector(MirrorCenterOptions options = {});

  // Finds centre, rim radius and annulus on an 8-bit grey image with nothing known but what
  // `geometry` gives (centre, r_min, r_max are used as given when present). Returns nullopt
  // if no circle is found (a message in *why when not null).
  std::optional<MirrorCircle> estimate(const cv::Mat& gray,
                                       const CameraGeometry& geometry,
                                       std::string* why = nullptr) const;

  // Per-frame detection with a known rim radius, searching within options.search_radius of
  // `prior.center`. The annulus r_min/r_max is carried over from `prior`. Returns nullopt if
  // the rim is not found (too few rim points), in which case the caller may keep the prior.
  std::optional<MirrorCircle> detect(const cv::Mat& gray,
                                     const MirrorCircle& prior,
                                     std::string* why = nullptr) const;

  // Sub-pixel refinement of centre and rim radius from a coarse circle (rays + robust
  // circle fit). Returns false if fewer than a quarter of the rays found the rim.
  bool refine(const cv::Mat& gray, Eigen::Vector2d& center, double& rim_radius) const;

  const MirrorCenterOptions& options() const { return options_; }

  // Image mask (image_mask.hpp: CV_8UC1, non-zero = usable) for the following calls, whose
  // images must have its size. Pixels whose Sobel window touches a masked pixel cast no
  // centre votes and do not count in the rim's coverage, and rays whose rim window touches
  // one give no rim point. An empty or all-usable mask: no mask (bit-identical results).
  void set_mask(const cv::Mat& usable);

 private:
  MirrorCenterOptions options_;
  // False when a pixel of the bilinear sample at p is masked.
  bool usable_at(const Eigen::Vector2d& p) const;
  cv::Mat usable_;  // the mask eroded by the Sobel radius; empty: no mask
};

}  // namespace omnivert
