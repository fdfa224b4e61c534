#include "omnivert/describe/feature_pipeline.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/image/grey.hpp"
#include "omnivert/image/image_mask.hpp"

namespace omnivert {

bool FeaturePipelineOptions::IsValid(std::string* why) const {
  return center.IsValid(why) && lines.IsValid(why) && descriptor.IsValid(why);
}

FrameDescriber::FrameDescriber(const CameraGeometry& geometry,
                               const FeaturePipelineOptions& options,
                               const cv::Mat& usable)
    : geometry_(&geometry), lines_(options.lines), descriptors_(options.descriptor) {
  if (!usable.empty()) {
    lines_.set_mask(usable);
    descriptors_.set_mask(usable);
  }
  if (!options.tilt.isZero() && geometry.has_projection())
    rectifier_.emplace(geometry, options.tilt);
}

void FrameDescriber::describe(const cv::Mat& gray, const MirrorCircle& circle, FrameFeatures& out) {
  out.circle = circle;
  const cv::Mat* frame = &gray;
  if (rectifier_) {
    rectifier_->apply(gray, out.circle, upright_);
    frame = &upright_;
  }
  lines_.extract(*frame, out.circle, out.lines);
  for (VerticalLine& l : out.lines) l.bearing = geometry_->bearing_of_image_angle(l.image_angle);
  descriptors_.compute(*frame, out.circle, out.lines, out.descriptors);
}

FeaturePipeline::FeaturePipeline(CameraGeometry geometry, FeaturePipelineOptions options)
    : geometry_(std::move(geometry)),
      options_(std::move(options)),
      center_(options_.center),
      describer_(geometry_, options_, cv::Mat()) {
  if (geometry_.mask) set_mask(read_mask(*geometry_.mask, geometry_.width, geometry_.height));
}

void FeaturePipeline::set_mask(const cv::Mat& usable) {
  CV_Assert(usable.empty() || usable.type() == CV_8UC1);
  mask_ = usable;
  center_.set_mask(usable);
  describer_.line_extractor().set_mask(usable);
  describer_.descriptor_extractor().set_mask(usable);
}

bool FeaturePipeline::to_gray8(const cv::Mat& image, cv::Mat& gray) {
  return to_grey8(image, PixelFormat{}, gray, nullptr);
}

double annulus_fraction_inside(const MirrorCircle& c, int width, int height) {
  int in = 0, total = 0;
  for (int i = 0; i < 32; ++i) {
    const double r = c.r_min + (c.r_max - c.r_min) * (i + 0.5) / 32.0;
    const double w = r;  // area element grows with r
    for (int k = 0; k < 180; ++k) {
      const double a = kTwoPi * k / 180.0;
      const double x = c.center.x() + r * std::cos(a), y = c.center.y() + r * std::sin(a);
      total += static_cast<int>(w);
      if (x >= 0 && y >= 0 && x <= width - 1 && y <= height - 1) in += static_cast<int>(w);
    }
  }
  return total ? static_cast<double>(in) / total : 0.0;
}

double annulus_fraction_usable(const MirrorCircle& c, const cv::Mat& usable) {
  double in = 0, ok = 0;
  for (int i = 0; i < 32; ++i) {
    const double r = c.r_min + (c.r_max - c.r_min) * (i + 0.5) / 32.0;
    for (int k = 0; k < 360; ++k) {
      const double a = kTwoPi * k / 360.0;
      const int x = static_cast<int>(std::lround(c.center.x() + r * std::cos(a)));
      const int y = static_cast<int>(std::lround(c.center.y() + r * std::sin(a)));
      if (x < 0 || y < 0 || x >= usable.cols || y >= usable.rows) continue;
      in += r;  // area element grows with r
      if (usable.at<uchar>(y, x)) ok += r;
    }
  }
  return in > 0 ? ok / in : 0.0;
}

bool FeaturePipeline::process(const cv::Mat& image, FrameFeatures& out, std::string* why) {
  MirrorCircle circle;
  if (!locate(image, gray_, circle, why)) return false;
  describer_.describe(gray_, circle, out);
  return true;
}

bool FeaturePipeline::locate(const cv::Mat& image,
                             cv::Mat& gray,
                             MirrorCircle& circle,
                             std::string* why) {
  if (why) why->clear();
  if (!to_grey8(image, geometry_.pixel_format, gray, why)) return false;
  if (geometry_.width > 0 && (gray.cols != geometry_.width || gray.rows != geometry_.height)) {
    if (why)
      *why = "image is " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows) +
             " but the camera's resolution is " + std::to_string(geometry_.width) + "x" +
             std::to_string(geometry_.height);
    return false;
  }
  const std::string mask_name = geometry_.mask ? "the mask " + *geometry_.mask : "the mask";
  if (!mask_.empty() && mask_.size() != gray.size()) {
    if (why)
      *why = mask_name + " is " + std::to_string(mask_.cols) + "x" + std::to_string(mask_.rows) +
             " but the image is " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows);
    return false;
  }
  // A centre given in sensor.yaml is used as it is (FeaturePipelineOptions).
  const bool center_as_given = geometry_.center && !options_.refine_given_center;
  if (!circle_) {
    std::string reason;
    auto c = center_.estimate(gray, geometry_, &reason);
    if (!c) {
      if (why) {
        *why = reason;
        if (!mask_.empty()) {
          const double usable = static_cast<double>(cv::countNonZero(mask_)) / mask_.total();
          *why += " (" + mask_name + " leaves " + std::to_string(std::lround(100 * usable)) +
                  "% of the image usable; the mirror rim must be usable, or sensor.yaml must "
                  "give center and r_max)";
        }
      }
      return false;
    }
    const double inside = annulus_fraction_inside(*c, gray.cols, gray.rows);
    if (inside < 0.25) {
      if (why) {
        char buf[256];
        std::snprintf(buf,
                      sizeof buf,
                      "the image (%dx%d) is smaller than the annulus r_min..r_max = %.1f..%.1f "
                      "px around (%.1f, %.1f): only %.0f%% of it is inside",
                      gray.cols,
                      gray.rows,
                      c->r_min,
                      c->r_max,
                      c->center.x(),
                      c->center.y(),
                      100 * inside);
        *why = buf;
      }
      return false;
    }
    if (center_as_given) c->center = *geometry_.center;
    if (!mask_.empty()) {
      const double usable = annulus_fraction_usable(*c, mask_);
      if (usable < kMinUsableAnnulus) {
        if (why) {
          std::vector<char> buf(mask_name.size() + 200);
          std::snprintf(buf.data(),
                        buf.size(),
                        "%s leaves only %.0f%% of the annulus r_min..r_max = %.1f..%.1f px "
                        "usable (at least %.0f%% is needed)",
                        mask_name.c_str(),
                        100 * usable,
                        c->r_min,
                        c->r_max,
                        100 * kMinUsableAnnulus);
          *why = buf.data();
        }
        return false;
      }
    }
    circle_ = c;
  } else if (options_.track_center && circle_->rim_radius > 0 && !center_as_given) {
    std::string reason;
    if (auto c = center_.detect(gray, *circle_, &reason)) {
      circle_ = c;
    } else if (why) {
      *why = reason + "; keeping the previous centre";
    }
  }
  circle = *circle_;
  return true;
}

}  // namespace omnivert
