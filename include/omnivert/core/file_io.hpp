#pragma once
// Writing output files so that an interrupted run never leaves a partial file under its final
// name.

#include <string>

namespace omnivert {

// Writes a text file atomically: to a temporary name in the same folder, then renamed. Throws
// InputError naming the file when the folder cannot be written or the write fails.
void write_text_atomic(const std::string& path, const std::string& text);

}  // namespace omnivert
