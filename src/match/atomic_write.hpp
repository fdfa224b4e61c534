#pragma once
// Internal: whole-file writes that never leave a partial file under the final name.

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "omnivert/core/error.hpp"

namespace omnivert::detail {

// Writes `bytes` to `path` through a temporary file in the same directory and a rename.
inline void write_atomically(const std::filesystem::path& path, const std::string& bytes) {
  std::filesystem::path tmp = path;
  tmp += ".partial";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw InputError(path.string(), 0, "cannot open for writing");
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    f.flush();
    if (!f) {
      f.close();
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw InputError(path.string(), 0, "write failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw InputError(path.string(), 0, "cannot rename the finished file into place");
  }
}

}  // namespace omnivert::detail
