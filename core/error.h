#pragma once
// Bad input is reported as one line naming the file (or option), the field, what was expected
// and what was found. The line is built here, once, and printed once by the program.
//
// Input never reaches an error line unbounded or raw: a quoted value shows at most kQuoteChars
// characters (then "..."), control bytes appear as \xNN (so a value cannot break the line or
// drive the terminal), and InputError bounds each of its parts the same way, whoever built them.
#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace isowall {

inline constexpr std::size_t kQuoteChars = 60;

// `text` with control bytes escaped as \xNN, cut after `max_chars` characters (never inside a
// UTF-8 sequence) and then marked with "...".
std::string clip(std::string_view text, std::size_t max_chars = kQuoteChars);
// clip(text) in double quotes: the one way an error shows a value the user gave.
std::string quote(std::string_view text);
// A file name or option for the start of an error line: control bytes escaped; past 120
// characters the middle is elided, so the end of a long path (the file's name) still shows.
std::string clip_source(std::string_view where);

class InputError : public std::runtime_error {
  public:
    // e.g. InputError("head.nhdr", "sizes", "expected 3 positive integers, got \"256 256\"")
    InputError(const std::string& where, const std::string& field, const std::string& message)
        : std::runtime_error(clip_source(where) + ": " + clip(field) + ": " +
                             clip(message, kMaxMessageChars)) {}

    // A message is ours plus quoted pieces of input; this only stops a runaway one.
    static constexpr std::size_t kMaxMessageChars = 400;

    // An InputError's line built in another process (readers/isolated_read.h), bounded
    // again here.
    static InputError relayed(std::string_view line) { return InputError(line); }

  private:
    explicit InputError(std::string_view line)
        : std::runtime_error(clip(line, 2 * kMaxMessageChars)) {}
};

}  // namespace isowall
