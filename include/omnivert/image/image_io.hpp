#pragma once
// Reading and writing images with user-facing errors.

#include <string>

#include <opencv2/core.hpp>

#include "omnivert/core/file_io.hpp"  // write_text_atomic

namespace omnivert {

// Reads an image file as it is stored (any depth, any channels). Throws InputError naming the
// file for a missing file, a directory, or a file that is not a readable image.
cv::Mat read_image(const std::string& path);

// Writes an image atomically (to a temporary name in the same folder, then renamed), so an
// interrupted write never leaves a partial file under the final name. Throws InputError for
// an unsupported extension or a folder that cannot be written.
void write_image_atomic(const std::string& path, const cv::Mat& image);

}  // namespace omnivert
