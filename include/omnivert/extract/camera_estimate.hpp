#pragma once
// The image-side geometry of a new camera from many frames: mirror centre, rim, valid
// annulus r_min..r_max and, from a moving robot's video, a proposed mask of the pixels that
// never change (the robot's own reflection, struts). What `omnivert camera` writes into
// cam0/sensor.yaml (docs/getting-started.md#write-cam0sensoryaml, docs/extraction.md).
//
// Each frame is estimated alone (MirrorCenterDetector::estimate); frames whose centre lies
// far from the median of all are dropped; the rim is then fitted once to the rim points of
// every kept frame together (one camera, one centre). The mask: a pixel of the annulus whose
// grey level varies over the frames much less than the scene's typical pixel does is static.

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/core/mirror_circle.hpp"
#include "omnivert/extract/mirror_center.hpp"

namespace omnivert {

struct CameraEstimateOptions {
  MirrorCenterOptions center;
  // A frame whose centre lies farther than max(this, 3 robust sigmas) from the median centre
  // is an outlier [px].
  double outlier_px = 1.0;
  // Mask: fewest frames that can show motion.
  int mask_min_frames = 5;
  // Mask: the frames show a moving scene when the median temporal standard deviation of the
  // annulus' pixels is at least this [grey levels]; below it there is no evidence.
  double mask_min_scene_std = 4.0;
  // Mask: a pixel is static when its temporal standard deviation (frames smoothed over 5x5
  // pixels and scaled to one mean level) is below this fraction of the annulus' median.
  double mask_static_fraction = 0.1;
  // Mask: static regions are grown by this many pixels (struts' blurred edges).
  int mask_grow_px = 2;
  // Mask: static regions smaller than this many pixels are dropped (a textureless patch of
  // the scene that happened to stay still).
  int mask_min_area_px = 200;

  bool IsValid(std::string* why) const;
};

struct FrameCircle {
  bool found = false;
  MirrorCircle circle;  // when found
  std::string why;      // when not found
  bool inlier = false;  // kept for the joint fit
};

struct CameraEstimate {
  int width = 0, height = 0;
  MirrorCircle circle;              // the joint estimate
  std::vector<FrameCircle> frames;  // one per input frame
  int used_frames = 0;              // frames kept for the joint fit
  double spread_px = 0;             // largest distance between two found frames' centres
  double rim_rms_px = 0;            // residual of the joint rim fit
  int rim_points = 0;               // rim points the joint fit kept
  cv::Mat mask;                     // CV_8U, non-zero = usable; empty when not proposed
  double masked_fraction = 0;       // of the annulus, when a mask is proposed
  std::string mask_note;            // why no mask was proposed
};

// Estimates the camera from 8-bit grey frames of one size. Throws InputError (file "", line 0)
// when the frames are empty or of different sizes, or when no frame shows a mirror rim (the
// message says what to give instead).
CameraEstimate estimate_camera(const std::vector<cv::Mat>& frames,
                               const CameraEstimateOptions& options = {});

// cam0/sensor.yaml text for the estimate: resolution, center, r_min, r_max, bearing_sign 1,
// rim_radius, and `mask: <mask_file>` when mask_file is not empty; each field commented.
std::string camera_sensor_yaml(const CameraEstimate& estimate,
                               const std::string& mask_file,
                               const std::string& provenance);

}  // namespace omnivert
