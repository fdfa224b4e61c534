#include "omnivert/core/file_io.hpp"

#include <filesystem>
#include <fstream>

#include "omnivert/core/error.hpp"

namespace omnivert {

namespace fs = std::filesystem;

void write_text_atomic(const std::string& path, const std::string& text) {
  const fs::path p(path);
  const fs::path tmp = p.parent_path() / (".tmp-" + p.filename().string());
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw InputError(path, 0, "cannot write (does the folder exist and is it writable?)");
    out << text;
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw InputError(path, 0, "write failed (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, p, ec);
  if (ec) throw InputError(path, 0, "cannot write: " + ec.message());
}

std::string unreadable_file_reason(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec == std::errc::too_many_symbolic_link_levels) return "is a loop of symbolic links";
  if (!fs::exists(st)) return "file not found";
  if (fs::is_directory(st)) return "is a directory";
  if (!fs::is_regular_file(st)) return "is not a regular file (a FIFO, a socket or a device)";
  return {};
}

}  // namespace omnivert
