#pragma once
// Pictures of a frame's features for people to look at: the mirror centre, the annulus, every
// extracted line (numbered as in the tool's table; the number red where the line is crowded)
// and the descriptor areas of one line.

#include <opencv2/core.hpp>

#include "omnivert/describe/descriptor.hpp"
#include "omnivert/describe/frame_features.hpp"

namespace omnivert {

// Returns a BGR picture. `highlight` is the index of the line whose circular areas are drawn
// (-1: the longest line).
cv::Mat draw_overlay(const cv::Mat& image,
                     const FrameFeatures& features,
                     const DescriptorExtractor& descriptor,
                     int highlight = -1);

}  // namespace omnivert
