#pragma once
// Writing output files so that an interrupted run never leaves a partial file under its final
// name.

#include <string>

namespace omnivert {

// Writes a text file atomically: to a temporary name in the same folder, then renamed. Throws
// InputError naming the file when the folder cannot be written or the write fails.
void write_text_atomic(const std::string& path, const std::string& text);

// Why `path` cannot be read as a file, in words for an InputError: "" for a regular file
// (symbolic links followed); "file not found", "is a loop of symbolic links", "is a
// directory" or "is not a regular file (a FIFO, a socket or a device)", which a reader must
// refuse rather than block on.
std::string unreadable_file_reason(const std::string& path);

}  // namespace omnivert
