#pragma once
// Pictures of a frame's features for people to look at: the mirror centre, the annulus, every
// extracted line (numbered as in the tool's table; the number red where the line is crowded)
// and the descriptor areas of one line.

#include <opencv2/core.hpp>

#include "omnivert/describe/descriptor.hpp"
#include "omnivert/describe/frame_features.hpp"
#include "omnivert/extract/camera_estimate.hpp"

namespace omnivert::viz {

// Returns a BGR picture. `highlight` is the index of the line whose circular areas are drawn
// (-1: the longest line).
cv::Mat draw_overlay(const cv::Mat& image,
                     const FrameFeatures& features,
                     const DescriptorExtractor& descriptor,
                     int highlight = -1);

// Returns a BGR picture of a camera estimate on one of its frames: the rim (yellow), the
// annulus r_min..r_max (blue), the centre (red cross), every frame's centre (green dots, at
// 10x their offset from the joint centre, so a spread of 1 px shows as 10 px) and the pixels
// the proposed mask excludes inside the annulus, tinted red.
cv::Mat draw_camera_overlay(const cv::Mat& image, const CameraEstimate& estimate);

}  // namespace omnivert::viz
