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
// Without a known rim radius, `estimate` finds the rim as a circle Hough transform (every
// edge pixel votes along its gradient line, for every radius from 30% of the image's
// smaller side up, so a rim darker or brighter outward counts alike) on a copy at most 320
// pixels across; each of the best thirty circles is refined on rays at full resolution (the
// strongest radial step of either sign near the circle, a robust circle fit) and the rim is
// the circle found within one pixel on the most rays (at least 30% of its circumference
// inside the image). Rays that leave the image are skipped, so a rim cut off by the frame is fitted
// on its visible arcs; the fit must hold a quarter of the rays and three quadrants of the circle
// (docs/extraction.md#mirror-centre-and-annulus). This is meant for one static image, as in the
// paper, and its result seeds `detect`; `estimate_camera` (extract/camera_estimate.hpp) combines
// many frames.

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
  // detect() first fits the rim on rays from the prior centre (the camera vibrates little
  // between frames) and keeps that fit when it moved the centre and the rim radius by at most
  // this many pixels; otherwise, or when it fails, it searches within search_radius (a Hough
  // vote, then the same fit). 0: always search.
  double track_px = 1.0;
  // detect() votes from a Sobel of the band's whole square and a test of every pixel in it,
  // instead of from the band's runs of pixels only. The same votes and centre to the bit
  // (test MirrorCenter.FastVotesEqualThePlainReference); kept to check the fast path.
  bool reference = false;

  bool IsValid(std::string* why) const;
};

class MirrorCenterDetector {
 public:
  explicit MirrorCenterDetector(MirrorCenterOptions options = {});

  // Finds centre, rim radius and annulus on an 8-bit grey image with nothing known but what
  // `geometry` gives (centre, r_min, r_max are used as given when present). Returns nullopt
  // if no rim is found (a message in *why, when not null, saying what to give instead).
  std::optional<MirrorCircle> estimate(const cv::Mat& gray,
                                       const CameraGeometry& geometry,
                                       std::string* why = nullptr) const;

  // Per-frame detection with a known rim radius: the rim fitted on rays from `prior.center`,
  // kept when it moved at most options.track_px; otherwise a search within
  // options.search_radius of `prior.center` (Hough votes, then the same fit). The annulus
  // r_min/r_max is carried over from `prior`. Returns nullopt if the rim is not found (too few rim
  // points), in which case the caller may keep the prior.
  std::optional<MirrorCircle> detect(const cv::Mat& gray,
                                     const MirrorCircle& prior,
                                     std::string* why = nullptr) const;

  // Sub-pixel refinement of centre and rim radius from a coarse circle (rays + robust
  // circle fit). Returns false if fewer than a quarter of the rays found the rim.
  bool refine(const cv::Mat& gray, Eigen::Vector2d& center, double& rim_radius) const;

  // Radius r_min of the valid annulus from the camera's self-reflection (a dark disc about
  // `center`, searched between 5% and 50% of r_max) plus inner_margin_fraction; 0.25 r_max
  // when no such disc is seen.
  double self_reflection_radius(const cv::Mat& gray,
                                const Eigen::Vector2d& center,
                                double r_max) const;

  const MirrorCenterOptions& options() const { return options_; }

  // Image mask (image_mask.hpp: CV_8UC1, non-zero = usable) for the following calls, whose
  // images must have its size. Pixels whose Sobel window touches a masked pixel cast no
  // centre votes and do not count in the rim's coverage, and rays whose rim window touches
  // one give no rim point. An empty or all-usable mask: no mask (bit-identical results).
  void set_mask(const cv::Mat& usable);

 private:
  MirrorCenterOptions options_;
  cv::Mat usable_;  // the mask eroded by the Sobel radius; empty: no mask
  // detect()'s Hough votes for the centre offset (accumulator acc, offset A at its middle)
  // from the edge pixels of the band R +- (S + 2) around the prior centre, inside roi.
  void vote_band(const cv::Mat& gray,
                 const MirrorCircle& prior,
                 const cv::Rect& roi,
                 int A,
                 cv::Mat& acc) const;
  void vote_band_reference(const cv::Mat& gray,
                           const MirrorCircle& prior,
                           const cv::Rect& roi,
                           int A,
                           cv::Mat& acc) const;
};

}  // namespace omnivert
