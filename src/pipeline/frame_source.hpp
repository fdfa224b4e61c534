#pragma once
// The frames of a dataset through the frame pipeline (Sec. 2-3), handed out in order and
// made a block at a time on several threads: images are read and described in parallel; the
// mirror circle is located frame after frame, since each frame's centre search starts from
// the previous one (Sec. 2 step 1). The frames are the same, bit for bit, for every thread
// count.

#include <cstddef>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/dataset/dataset.hpp"
#include "omnivert/describe/feature_pipeline.hpp"

namespace omnivert::pipeline {

class FrameSource {
 public:
  struct Frame {
    bool ok = false;                    // false: the frame is skipped (its warnings say why)
    FrameFeatures features;             // when ok
    std::vector<std::string> warnings;  // what FeaturePipeline::process would have said
  };

  // `pipe` locates the circles (and must outlive the source); threads as resolve_threads.
  FrameSource(const dataset::Dataset& data, FeaturePipeline& pipe, int threads);

  // The next frame (data.images() order); valid until the next call. At most data.size()
  // calls.
  const Frame& next();

 private:
  void fill();

  const dataset::Dataset& data_;
  FeaturePipeline& pipe_;
  int threads_;
  std::vector<FrameDescriber> describers_;
  std::vector<Frame> block_;
  std::vector<cv::Mat> images_;
  std::vector<cv::Mat> grays_;
  std::vector<MirrorCircle> circles_;
  std::size_t start_ = 0;  // dataset index of block_[0]
  std::size_t size_ = 0;   // frames in the block
  std::size_t pos_ = 0;    // next frame of the block to hand out
};

}  // namespace omnivert::pipeline
