#pragma once
// Shared by the libFuzzer harnesses (scripts/fuzz, docs/validation.md#fuzzing): a scratch
// folder for the files a harness writes, and the rule every harness checks: a reader either
// succeeds or throws omnivert::InputError; any other exception, a crash or undefined
// behaviour is a finding.

#include <unistd.h>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "omnivert/core/error.hpp"

namespace omnivert::fuzz {

// A fresh folder under /dev/shm (or the temporary folder), removed at exit.
inline const std::filesystem::path& scratch() {
  static const std::filesystem::path dir = [] {
    std::error_code ec;
    const std::filesystem::path base = std::filesystem::is_directory("/dev/shm", ec)
                                           ? std::filesystem::path("/dev/shm")
                                           : std::filesystem::temp_directory_path();
    std::string tmpl = (base / "omnivert-fuzz-XXXXXX").string();
    if (!mkdtemp(tmpl.data())) std::abort();
    static const std::string keep = tmpl;
    std::atexit([] {
      std::error_code e;
      std::filesystem::remove_all(keep, e);
    });
    return std::filesystem::path(tmpl);
  }();
  return dir;
}

inline void write_file(const std::filesystem::path& path, std::string_view bytes) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) std::abort();
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Runs a reader; InputError is the expected way to refuse an input.
template <typename F>
void expect_input_error_or_success(F&& read) {
  try {
    read();
  } catch (const omnivert::InputError&) {
  }
}

}  // namespace omnivert::fuzz
