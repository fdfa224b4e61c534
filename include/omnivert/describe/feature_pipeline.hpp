#pragma once
// One frame from pixels to features: mirror circle (Sec. 2 step 1), radial lines (Sec. 2
// steps 2-5), descriptors (Sec. 3). Keeps the state a video needs: the rim radius found on
// the first frame and the previous centre, which seeds the per-frame centre search.

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/describe/descriptor.hpp"
#include "omnivert/describe/frame_features.hpp"
#include "omnivert/extract/line_extractor.hpp"
#include "omnivert/extract/mirror_center.hpp"
#include "omnivert/extract/tilt_estimator.hpp"

namespace omnivert {

struct FeaturePipelineOptions {
  MirrorCenterOptions center;
  LineExtractorOptions lines;
  DescriptorOptions descriptor;
  // Detect the centre on every frame (the platform vibrates, Sec. 2). If false, the centre
  // of the first frame is kept.
  bool track_center = true;
  // A centre given in sensor.yaml is used as given on every frame: it is the camera's
  // calibration, and the rim fit that would replace it is pulled by the scene just inside the
  // rim (rendered tours: 0.0065 px along the robot's axis in every world, which moved the
  // calibrated camera 0.14 mm forward; docs/theory/extraction.md#a-given-centre). True: the given
  // centre only seeds the search, and the centre is fitted and tracked as without it.
  bool refine_given_center = false;
  // Tilt vector t (cos d, sin d) [rad] of the mirror axis (core/tilt.hpp). Non-zero, with the
  // camera's xi and gamma known: every frame is rectified to the upright camera before the
  // lines are extracted and described, so that their bearings are the upright ones of
  // eq. (16)-(17) (docs/theory/tilt.md). Zero: frames are used as they are.
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();

  bool IsValid(std::string* why) const;
};

// The second half of a frame's processing (Sec. 2 steps 2-5, Sec. 3): radial lines and
// descriptors of a grey frame whose mirror circle is known. It keeps only scratch buffers, so
// frames may be described in any order; one FrameDescriber per thread describes frames in
// parallel with results identical to one describer in order.
class FrameDescriber {
 public:
  // `usable`: the image mask (image_mask.hpp; empty: none).
  FrameDescriber(const CameraGeometry& geometry,
                 const FeaturePipelineOptions& options,
                 const cv::Mat& usable);

  // Lines (bearings by the camera's geometry) and descriptors of `gray` (8-bit), whose
  // mirror circle is `circle`: out.circle, out.lines and out.descriptors are replaced.
  // With a tilt, the frame is first rectified to the upright camera.
  void describe(const cv::Mat& gray, const MirrorCircle& circle, FrameFeatures& out);

  LineExtractor& line_extractor() { return lines_; }
  DescriptorExtractor& descriptor_extractor() { return descriptors_; }

 private:
  const CameraGeometry* geometry_;  // the owning pipeline's (outlives its describers)
  LineExtractor lines_;
  DescriptorExtractor descriptors_;
  std::optional<TiltRectifier> rectifier_;
  cv::Mat upright_;
};

class FeaturePipeline {
 public:
  // With geometry.mask set, reads that mask (read_mask: InputError naming the mask file) and
  // hands it to every stage (set_mask).
  FeaturePipeline(CameraGeometry geometry, FeaturePipelineOptions options = {});
  FeaturePipeline(const FeaturePipeline&) = delete;
  FeaturePipeline& operator=(const FeaturePipeline&) = delete;

  // Image mask for every stage (image_mask.hpp: CV_8UC1, non-zero = usable; empty: none).
  // The first frame is refused when less than kMinUsableAnnulus of the annulus is usable.
  void set_mask(const cv::Mat& usable);
  const cv::Mat& mask() const { return mask_; }
  static constexpr double kMinUsableAnnulus = 0.2;

  // Processes one image (8-bit or 16-bit, grey, colour or a Bayer mosaic: converted to 8-bit
  // grey by to_grey8 with the camera's pixel_format). Returns
  // false with a reason in *why for an image that does not fit the camera (wrong size, the
  // annulus mostly outside the image) or whose mirror cannot be found on the first frame.
  // A later frame whose rim is not found keeps the previous centre (and says so in *why,
  // while still returning true). The same as locate() then describe() of describer().
  bool process(const cv::Mat& image, FrameFeatures& out, std::string* why = nullptr);

  // The first half of process(): the 8-bit grey frame and its mirror circle (Sec. 2 step 1).
  // It keeps the state a video needs (the rim found on the first frame, the previous centre
  // seeding the next search), so frames must be located one after another, in order. Returns
  // false, with the reason, as process() does.
  bool locate(const cv::Mat& image,
              cv::Mat& gray,
              MirrorCircle& circle,
              std::string* why = nullptr);

  // A describer of this pipeline's camera, options and mask, for another thread (it refers
  // to this pipeline's geometry: the pipeline must outlive it). set_mask() does not reach the
  // describers made before it.
  FrameDescriber make_describer() const { return FrameDescriber(geometry_, options_, mask_); }

  // Converts a grey or colour image to 8-bit grey (to_grey8 with the default PixelFormat);
  // false if the type is not supported.
  static bool to_gray8(const cv::Mat& image, cv::Mat& gray);

  const CameraGeometry& geometry() const { return geometry_; }
  const std::optional<MirrorCircle>& circle() const { return circle_; }
  const FeaturePipelineOptions& options() const { return options_; }
  LineExtractor& line_extractor() { return describer_.line_extractor(); }
  DescriptorExtractor& descriptor_extractor() { return describer_.descriptor_extractor(); }

 private:
  CameraGeometry geometry_;
  FeaturePipelineOptions options_;
  MirrorCenterDetector center_;
  FrameDescriber describer_;
  std::optional<MirrorCircle> circle_;
  cv::Mat gray_;
  cv::Mat mask_;
};

// Fraction of the annulus r_min..r_max around `circle.center` that lies inside a w x h image.
double annulus_fraction_inside(const MirrorCircle& circle, int width, int height);

// Fraction of the annulus r_min..r_max around `circle.center`, inside the mask's image, that
// the mask leaves usable (area-weighted samples, as above).
double annulus_fraction_usable(const MirrorCircle& circle, const cv::Mat& usable);

}  // namespace omnivert
