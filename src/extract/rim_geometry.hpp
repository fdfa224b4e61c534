#pragma once
// Circle geometry shared by the mirror-centre detector and the camera estimate: bilinear
// sampling, robust circle fits, the circle Hough transform and the ray search for rim points
// (docs/extraction.md#mirror-centre-and-annulus).

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace omnivert::rim {

// Bilinear sample of an 8-bit image; false outside.
bool sample(const cv::Mat& img, double x, double y, double& out);
// True when the four pixels of a bilinear sample at p are usable (p inside the image).
bool usable_at(const cv::Mat& usable, const Eigen::Vector2d& p);

// Least-squares circle through points: algebraic (Kasa) start, then Gauss-Newton on the
// geometric distance, with outliers beyond 3 robust sigmas removed between passes. When
// `kept` is not null it receives the points of the last pass.
bool fit_circle(std::vector<Eigen::Vector2d> pts,
                Eigen::Vector2d& c,
                double& r,
                std::vector<Eigen::Vector2d>* kept = nullptr);

// Smooths an accumulator and returns the position of its maximum (with a parabolic sub-pixel
// step in each axis).
Eigen::Vector2d accumulator_peak(cv::Mat& acc, double sigma);

// Fraction of the in-image circumference at each integer radius covered by edge pixels with
// a radial gradient of the given sign (+1: brighter outward, -1: darker outward, 0: either),
// smoothed over +-1 pixel. Masked pixels (`usable` zero; empty: none) count neither way.
std::vector<double> radial_edge_coverage(const cv::Mat& gx,
                                         const cv::Mat& gy,
                                         const Eigen::Vector2d& c,
                                         int r_max,
                                         double threshold,
                                         int sign,
                                         const cv::Mat& usable = cv::Mat());

struct CircleCandidate {
  Eigen::Vector2d center;
  double radius = 0;
  double score = 0;  // votes per pixel of radius (about 2 pi x the covered fraction)
};

// Circle Hough transform with gradient directions: every edge pixel (Sobel magnitude >=
// threshold) votes, for every radius in [r_lo, r_hi], at the two points one radius away
// along its gradient line, so either polarity counts. Centres lie inside the image. Returns
// up to `count` peaks, best first, at least `separation` pixels apart in centre or radius.
// Masked edge pixels (`usable` zero; empty: none) cast no vote.
std::vector<CircleCandidate> hough_circles(const cv::Mat& gray,
                                           int r_lo,
                                           int r_hi,
                                           double threshold,
                                           int count,
                                           double separation,
                                           const cv::Mat& usable = cv::Mat());

// A rim fitted from points found along rays.
struct RimFit {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double radius = 0;
  int rays_inside = 0;  // rays whose search window lies inside the image
  int inliers = 0;      // rim points the final fit kept
  int quadrants = 0;    // quadrants of the circle (about the centre) holding inliers
  int close = 0;        // kept points within 1 pixel of the circle
  double rms = 0;       // residual of the kept points [px]
  std::vector<Eigen::Vector2d> points;  // the kept points
  // Fraction of the visible circumference on which the rim was found within 1 pixel.
  double coverage() const { return rays_inside > 0 ? double(close) / rays_inside : 0.0; }
};

// Rim points along `rays` rays from `center`, each the sub-pixel position of the strongest
// radial intensity step of either sign within +-window of `radius` (at least 4 grey levels
// per pixel), then a robust circle fit. Rays whose window leaves the image are skipped, so a
// rim partly outside the image is fitted on its visible arcs. Returns false when fewer than
// 8 points were found or the fit fails. A ray whose window touches a masked pixel (`usable`
// zero; empty: none) is skipped like one that leaves the image.
bool fit_rim_on_rays(const cv::Mat& gray,
                     const Eigen::Vector2d& center,
                     double radius,
                     double window,
                     int rays,
                     RimFit& out,
                     const cv::Mat& usable = cv::Mat());

}  // namespace omnivert::rim
