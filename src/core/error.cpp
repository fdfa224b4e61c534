#include "omnivert/core/error.hpp"

namespace omnivert {

// Out of line: GCC 12 reports a false -Wrestrict on this concatenation when it is inlined.
std::string InputError::format(const std::string& file, int line, const std::string& problem) {
  std::string s;
  if (!file.empty()) {
    s.append(file);
    if (line > 0) s.append(":").append(std::to_string(line));
    s.append(": ");
  }
  s.append(problem);
  return s;
}

}  // namespace omnivert
