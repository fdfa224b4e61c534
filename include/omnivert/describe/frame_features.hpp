#pragma once
// Everything the pipeline keeps of one frame after extraction and description: the mirror
// circle, the vertical lines and their descriptors (row i of `descriptors` describes
// lines[i]).

#include <vector>

#include <Eigen/Core>

#include "omnivert/core/mirror_circle.hpp"
#include "omnivert/core/vertical_line.hpp"

namespace omnivert {

// One descriptor per row. The paper's descriptor has 192 columns (eq. 5); other settings
// (8/16 bins, five areas) give other widths, so the width is dynamic.
using DescriptorMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

inline constexpr int kPaperDescriptorSize = 192;  // 3 areas x 2 halves x 32 bins, eq. (5)

struct FrameFeatures {
  MirrorCircle circle;
  std::vector<VerticalLine> lines;
  DescriptorMatrix descriptors;
};

}  // namespace omnivert
