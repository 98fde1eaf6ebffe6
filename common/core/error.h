#pragma once
// Bad input is reported as one line naming the file (or option), the field, what was expected
// and what was found. The line is built here, once, and printed once by the program.
#include <stdexcept>
#include <string>

namespace isowall {

class InputError : public std::runtime_error {
  public:
    // e.g. InputError("head.nhdr", "sizes", "expected 3 positive integers, got \"256 256\"")
    InputError(const std::string& where, const std::string& field, const std::string& message)
        : std::runtime_error(where + ": " + field + ": " + message) {}
};

}  // namespace isowall
