#pragma once
// A one-line progress display for long work. It draws on stderr only when stderr is a
// terminal, and stays quiet otherwise (logs, CI, pipes).

#include <chrono>
#include <cstddef>
#include <string>

namespace omnivert {

class Progress {
 public:
  Progress(std::string label, std::size_t total);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Sets the number of items done; redraws at most ten times a second.
  void update(std::size_t done);
  // Draws the final state and ends the line.
  void finish();

  static bool enabled();

 private:
  void draw(std::size_t done);
  std::string label_;
  std::size_t total_;
  bool active_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace omnivert
