#pragma once
// Errors that a user can fix: bad files, bad values. The library throws InputError for
// those (with the file, the line when there is one, and what is wrong); the CLI prints the
// message and exits non-zero. Broken internal contracts are asserts, not InputErrors.

#include <stdexcept>
#include <string>

namespace omnivert {

class InputError : public std::runtime_error {
 public:
  // file may be empty (input that is not a file); line <= 0 means "no line".
  InputError(std::string file, int line, const std::string& problem)
      : std::runtime_error(format(file, line, problem)), file_(std::move(file)), line_(line) {}
  explicit InputError(const std::string& problem) : InputError("", 0, problem) {}

  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  static std::string format(const std::string& file, int line, const std::string& problem);
  std::string file_;
  int line_;
};

}  // namespace omnivert
