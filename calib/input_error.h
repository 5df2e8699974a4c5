#pragma once

#include <stdexcept>
#include <string>

namespace raycarve {

// Thrown for bad user input: a file that cannot be read, a malformed or inconsistent model, a
// missing image. The message names the file (or source) and the field; the command line prints
// it as one line and exits non-zero. Broken internal invariants use CHECK instead.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace raycarve
