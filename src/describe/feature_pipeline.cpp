#include "omnivert/describe/feature_pipeline.hpp"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"

namespace omnivert {

bool FeaturePipelineOptions::IsValid(std::string* why) const {
  return center.IsValid(why) && lines.IsValid(why) && descriptor.IsValid(why);
}

FeaturePipeline::FeaturePipeline(CameraGeometry geometry, FeaturePipelineOptions options)
    : geometry_(std::move(geometry)),
      options_(std::move(options)),
      center_(options_.center),
      lines_(options_.lines),
      descriptors_(options_.descriptor) {
  if (!options_.tilt.isZero() && geometry_.has_projection())
    rectifier_.emplace(geometry_, options_.tilt);
}

bool FeaturePipeline::to_gray8(const cv::Mat& image, cv::Mat& gray) {
  if (image.empty() || image.dims != 2) return false;
  cv::Mat g;
  switch (image.channels()) {
    case 1:
      g = image;
      break;
    case 3:
      cv::cvtColor(image, g, cv::COLOR_BGR2GRAY);
      break;
    case 4:
      cv::cvtColor(image, g, cv::COLOR_BGRA2GRAY);
      break;
    default:
      return false;
  }
  switch (g.depth()) {
    case CV_8U:
      gray = g.isContinuous() ? g : g.clone();
      return true;
    case CV_16U:
      g.convertTo(gray, CV_8U, 1.0 / 257.0);
      return true;
    case CV_32F:
    case CV_64F:
      g.convertTo(gray, CV_8U, 255.0);
      return true;
    default:
      return false;
  }
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

bool FeaturePipeline::process(const cv::Mat& image, FrameFeatures& out, std::string* why) {
  if (why) why->clear();
  if (!to_gray8(image, gray_)) {
    if (why) *why = "unsupported image type (expected 8- or 16-bit grey or colour)";
    return false;
  }
  if (geometry_.width > 0 && (gray_.cols != geometry_.width || gray_.rows != geometry_.height)) {
    if (why)
      *why = "image is " + std::to_string(gray_.cols) + "x" + std::to_string(gray_.rows) +
             " but the camera's resolution is " + std::to_string(geometry_.width) + "x" +
             std::to_string(geometry_.height);
    return false;
  }
  // A centre given in sensor.yaml is used as it is (FeaturePipelineOptions).
  const bool center_as_given = geometry_.center && !options_.refine_given_center;
  if (!circle_) {
    std::string reason;
    auto c = center_.estimate(gray_, geometry_, &reason);
    if (!c) {
      if (why) *why = reason;
      return false;
    }
    const double inside = annulus_fraction_inside(*c, gray_.cols, gray_.rows);
    if (inside < 0.25) {
      if (why) {
        char buf[256];
        std::snprintf(buf,
                      sizeof buf,
                      "the image (%dx%d) is smaller than the annulus r_min..r_max = %.1f..%.1f "
                      "px around (%.1f, %.1f): only %.0f%% of it is inside",
                      gray_.cols,
                      gray_.rows,
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
    circle_ = c;
  } else if (options_.track_center && circle_->rim_radius > 0 && !center_as_given) {
    std::string reason;
    if (auto c = center_.detect(gray_, *circle_, &reason)) {
      circle_ = c;
    } else if (why) {
      *why = reason + "; keeping the previous centre";
    }
  }
  out.circle = *circle_;
  const cv::Mat* frame = &gray_;
  if (rectifier_) {
    rectifier_->apply(gray_, out.circle, upright_);
    frame = &upright_;
  }
  lines_.extract(*frame, out.circle, out.lines);
  for (VerticalLine& l : out.lines) l.bearing = geometry_.bearing_of_image_angle(l.image_angle);
  descriptors_.compute(*frame, out.circle, out.lines, out.descriptors);
  return true;
}

}  // namespace omnivert
