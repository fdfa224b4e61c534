#include "omnivert/extract/camera_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "extract/rim_geometry.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert {

bool CameraEstimateOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!center.IsValid(why)) return false;
  if (!(outlier_px > 0)) return fail("outlier_px must be positive");
  if (mask_min_frames < 2) return fail("mask_min_frames must be at least 2");
  if (!(mask_min_scene_std > 0)) return fail("mask_min_scene_std must be positive");
  if (!(mask_static_fraction > 0 && mask_static_fraction < 1))
    return fail("mask_static_fraction must be in (0, 1)");
  if (mask_grow_px < 0) return fail("mask_grow_px must not be negative");
  if (mask_min_area_px < 0) return fail("mask_min_area_px must not be negative");
  return true;
}

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + v.size() / 2;
  std::nth_element(v.begin(), mid, v.end());
  if (v.size() % 2) return *mid;
  return 0.5 * (*mid + *std::max_element(v.begin(), mid));
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// Frames whose centre lies within max(outlier_px, 3 robust sigmas) of the median centre.
void mark_inliers(std::vector<FrameCircle>& frames, double outlier_px) {
  std::vector<double> xs, ys;
  for (const auto& f : frames)
    if (f.found) xs.push_back(f.circle.center.x()), ys.push_back(f.circle.center.y());
  const Eigen::Vector2d med(median(xs), median(ys));
  std::vector<double> dist;
  for (const auto& f : frames)
    if (f.found) dist.push_back((f.circle.center - med).norm());
  const double gate = std::max(outlier_px, 3.0 * 1.4826 * median(dist));
  for (auto& f : frames) f.inlier = f.found && (f.circle.center - med).norm() <= gate;
}

// The proposed mask (docs/extraction.md#mask-proposal): usable = inside the annulus and not
// static. Leaves `e.mask` empty and says why in `e.mask_note` when the frames show no motion.
void propose_mask(const std::vector<cv::Mat>& frames,
                  const CameraEstimateOptions& o,
                  CameraEstimate& e) {
  if (static_cast<int>(frames.size()) < o.mask_min_frames) {
    e.mask_note = "no mask proposed: " + std::to_string(frames.size()) +
                  " frame(s); a mask needs at least " + std::to_string(o.mask_min_frames) +
                  " frames of a moving robot";
    return;
  }
  cv::Mat annulus = cv::Mat::zeros(frames[0].size(), CV_8U);
  const cv::Point c(static_cast<int>(std::lround(e.circle.center.x())),
                    static_cast<int>(std::lround(e.circle.center.y())));
  cv::circle(annulus, c, static_cast<int>(e.circle.r_max), 255, cv::FILLED);
  cv::circle(annulus, c, static_cast<int>(e.circle.r_min), 0, cv::FILLED);
  // Temporal standard deviation of each pixel over frames smoothed over 5x5 pixels (sensor
  // noise / 5) and divided by their mean level in the annulus (the camera's gain and
  // exposure changes), so that a still pixel's deviation is near zero.
  cv::Mat sum = cv::Mat::zeros(frames[0].size(), CV_64F), sq = sum.clone(), f64;
  for (const auto& f : frames) {
    cv::blur(f, f64, {5, 5});
    f64.convertTo(f64, CV_64F);
    const double level = cv::mean(f64, annulus)[0];
    if (level > 1.0) f64 *= 128.0 / level;
    sum += f64;
    sq += f64.mul(f64);
  }
  const double n = static_cast<double>(frames.size());
  cv::Mat var = sq / n - (sum / n).mul(sum / n), sd;
  cv::max(var, 0.0, var);
  cv::sqrt(var, sd);
  std::vector<double> sds;
  for (int v = 0; v < sd.rows; v += 2)
    for (int u = 0; u < sd.cols; u += 2)
      if (annulus.at<uchar>(v, u)) sds.push_back(sd.at<double>(v, u));
  const double scene = median(sds);
  if (!(scene >= o.mask_min_scene_std)) {
    e.mask_note =
        "no mask proposed: the frames hardly change (median temporal standard "
        "deviation " +
        fmt("%.1f", scene) +
        " grey levels inside the annulus); record frames while the robot moves";
    return;
  }
  cv::Mat stat = (sd < o.mask_static_fraction * scene) & annulus;
  // Cleanup: drop specks and small still patches of the scene, close gaps, grow the rest.
  const cv::Mat k3 = cv::getStructuringElement(cv::MORPH_ELLIPSE, {3, 3});
  cv::morphologyEx(stat, stat, cv::MORPH_OPEN, k3);
  cv::morphologyEx(
      stat, stat, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, {7, 7}));
  cv::Mat labels, stats, centroids;
  const int nl = cv::connectedComponentsWithStats(stat, labels, stats, centroids, 8, CV_32S);
  for (int v = 0; v < labels.rows; ++v)
    for (int u = 0; u < labels.cols; ++u) {
      const int l = labels.at<int>(v, u);
      if (l > 0 && l < nl && stats.at<int>(l, cv::CC_STAT_AREA) < o.mask_min_area_px)
        stat.at<uchar>(v, u) = 0;
    }
  if (o.mask_grow_px > 0) {
    const int k = 2 * o.mask_grow_px + 1;
    cv::dilate(stat, stat, cv::getStructuringElement(cv::MORPH_ELLIPSE, {k, k}));
  }
  const double area = cv::countNonZero(annulus);
  const double excluded = cv::countNonZero(stat);
  if (!(excluded >= o.mask_min_area_px)) {
    e.mask_note =
        "no mask proposed: nothing inside the annulus stays still while the scene "
        "changes";
    return;
  }
  e.mask = annulus & ~stat;
  e.masked_fraction = area > 0 ? excluded / area : 0.0;
}

}  // namespace

CameraEstimate estimate_camera(const std::vector<cv::Mat>& frames, const CameraEstimateOptions& o) {
  if (frames.empty()) throw InputError("no frames given");
  CameraEstimate e;
  e.width = frames[0].cols;
  e.height = frames[0].rows;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].size() != frames[0].size() || frames[i].type() != CV_8UC1)
      throw InputError("frame " + std::to_string(i) + " is not an 8-bit grey image of " +
                       std::to_string(e.width) + "x" + std::to_string(e.height) + " pixels");
  }
  const MirrorCenterDetector det(o.center);
  CameraGeometry none;
  none.width = e.width;
  none.height = e.height;
  for (const auto& f : frames) {
    FrameCircle fc;
    if (auto c = det.estimate(f, none, &fc.why)) fc.found = true, fc.circle = *c;
    e.frames.push_back(fc);
  }
  int found = 0;
  for (std::size_t i = 0; i < e.frames.size(); ++i) {
    if (!e.frames[i].found) continue;
    ++found;
    for (std::size_t j = i + 1; j < e.frames.size(); ++j)
      if (e.frames[j].found)
        e.spread_px =
            std::max(e.spread_px, (e.frames[i].circle.center - e.frames[j].circle.center).norm());
  }
  if (found == 0) {
    // The detector's reason without its advice for a single image.
    const std::string& why = e.frames[0].why;
    throw InputError(why.substr(0, why.find(';')) + ", in any of the " +
                     std::to_string(frames.size()) +
                     " frame(s); write cam0/sensor.yaml by hand with resolution, center, r_min "
                     "and r_max (docs/dataset-format.md)");
  }
  mark_inliers(e.frames, o.outlier_px);

  // Joint fit: the rim points of every kept frame, found along rays from the median circle.
  std::vector<double> cx, cy, rr, rmin;
  for (const auto& f : e.frames) {
    if (!f.inlier) continue;
    cx.push_back(f.circle.center.x());
    cy.push_back(f.circle.center.y());
    rr.push_back(f.circle.rim_radius);
    rmin.push_back(f.circle.r_min);
  }
  const Eigen::Vector2d c0(median(cx), median(cy));
  const double r0 = median(rr);
  std::vector<Eigen::Vector2d> pts;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (!e.frames[i].inlier) continue;
    rim::RimFit fit;
    if (!rim::fit_rim_on_rays(frames[i], c0, r0, o.center.rim_window, o.center.rim_rays, fit))
      continue;
    pts.insert(pts.end(), fit.points.begin(), fit.points.end());
    ++e.used_frames;
  }
  e.circle.center = c0;
  e.circle.rim_radius = r0;
  std::vector<Eigen::Vector2d> kept;
  Eigen::Vector2d c = c0;
  double r = r0;
  if (rim::fit_circle(pts, c, r, &kept) && (c - c0).norm() <= o.outlier_px + 1.0) {
    e.circle.center = c;
    e.circle.rim_radius = r;
    e.rim_points = static_cast<int>(kept.size());
    double ss = 0;
    for (const auto& p : kept) ss += std::pow((p - c).norm() - r, 2);
    e.rim_rms_px = std::sqrt(ss / std::max<std::size_t>(1, kept.size()));
  }
  e.circle.r_max = e.circle.rim_radius * (1.0 - o.center.rim_margin_fraction);
  e.circle.r_min = median(rmin);
  if (!(e.circle.r_min < e.circle.r_max)) e.circle.r_min = 0.25 * e.circle.r_max;
  propose_mask(frames, o, e);
  return e;
}

std::string camera_sensor_yaml(const CameraEstimate& e,
                               const std::string& mask_file,
                               const std::string& provenance) {
  std::string y = "# cam0/sensor.yaml: " + provenance + "\n";
  y += "# Check it on the overlay picture and edit it as needed (docs/dataset-format.md).\n";
  y += "resolution: [" + std::to_string(e.width) + ", " + std::to_string(e.height) +
       "]   # image width, height [px]\n";
  y += "center: [" + fmt("%.2f", e.circle.center.x()) + ", " + fmt("%.2f", e.circle.center.y()) +
       "]   # mirror centre [px]: the centre of the rim circle\n";
  y += "r_min: " + fmt("%.1f", e.circle.r_min) +
       "   # inner radius of the valid annulus [px]: the camera's own reflection + margin\n";
  y += "r_max: " + fmt("%.1f", e.circle.r_max) +
       "   # outer radius of the valid annulus [px]: the mirror rim - margin\n";
  y += "bearing_sign: 1   # -1 when the image is mirror-flipped (docs/getting-started.md)\n";
  y += "rim_radius: " + fmt("%.2f", e.circle.rim_radius) +
       "   # the mirror rim [px], for reference (not read)\n";
  if (!mask_file.empty())
    y += "mask: " + mask_file + "   # usable pixels are non-zero; the rest is never used\n";
  return y;
}

}  // namespace omnivert
