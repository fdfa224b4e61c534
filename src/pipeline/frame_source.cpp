#include "pipeline/frame_source.hpp"

#include <algorithm>
#include <stdexcept>

#include "core/parallel.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::pipeline {

namespace {
// Frames per thread in a block: enough to keep the threads busy between the serial steps,
// few enough to bound the memory (a block's images are held at once).
constexpr std::size_t kFramesPerThread = 4;
}  // namespace

FrameSource::FrameSource(const dataset::Dataset& data, FeaturePipeline& pipe, int threads)
    : data_(data), pipe_(pipe), threads_(resolve_threads(threads)) {
  describers_.reserve(static_cast<std::size_t>(threads_));
  for (int t = 0; t < threads_; ++t) describers_.push_back(pipe_.make_describer());
  const std::size_t block = kFramesPerThread * static_cast<std::size_t>(threads_);
  block_.resize(block);
  images_.resize(block);
  grays_.resize(block);
  circles_.resize(block);
}

const FrameSource::Frame& FrameSource::next() {
  if (pos_ == size_) fill();
  if (pos_ == size_) throw std::out_of_range("FrameSource: no frame left");
  return block_[pos_++];
}

void FrameSource::fill() {
  start_ += size_;
  pos_ = 0;
  size_ = std::min(block_.size(), data_.size() - std::min(start_, data_.size()));
  if (size_ == 0) return;
  std::vector<char> located(size_, 0);
  // Read (in parallel): an image that cannot be read skips its frame.
  parallel_for(size_, threads_, [&](std::size_t k, int) {
    Frame& fr = block_[k];
    fr.ok = false;
    fr.warnings.clear();
    try {
      images_[k] = data_.image(start_ + k);
      located[k] = 1;
    } catch (const InputError& e) {
      images_[k].release();
      fr.warnings.push_back(std::string(e.what()) + "; frame " + std::to_string(start_ + k) +
                            " skipped");
    }
  });
  // Locate (in order): the circle of each frame seeds the next frame's search.
  for (std::size_t k = 0; k < size_; ++k) {
    if (!located[k]) continue;
    Frame& fr = block_[k];
    const std::string& path = data_.images()[start_ + k].path;
    const std::string frame = std::to_string(start_ + k);
    try {
      std::string why;
      fr.ok = pipe_.locate(images_[k], grays_[k], circles_[k], &why);
      if (!fr.ok) {
        fr.warnings.push_back(path + ": " + why + "; frame " + frame + " skipped");
      } else if (!why.empty()) {
        fr.warnings.push_back(path + ": " + why);
      }
    } catch (const InputError& e) {
      fr.ok = false;
      fr.warnings.push_back(std::string(e.what()) + "; frame " + frame + " skipped");
    }
    images_[k].release();
  }
  // Describe (in parallel): lines and descriptors, one describer per thread.
  parallel_for(size_, threads_, [&](std::size_t k, int worker) {
    if (block_[k].ok) {
      describers_[static_cast<std::size_t>(worker)].describe(
          grays_[k], circles_[k], block_[k].features);
    }
    grays_[k].release();
  });
}

}  // namespace omnivert::pipeline
