#pragma once
// Running the isowall program from tests: its exit code and output, and the one-line error rule.
#include <filesystem>
#include <initializer_list>
#include <string>
#include <vector>

#include "tests/test_util.h"  // slurp

namespace isowall::test {

struct RunResult {
    int exit_code = -1;
    std::string out, err;
};

// Runs the real binary in `dir` under `timeout`, so a hang fails the test instead of the suite;
// stdout and stderr go to dir/stdout.txt and dir/stderr.txt. `prefix` goes before the binary
// (e.g. "setpriv ... ").
RunResult run_isowall(const std::filesystem::path& dir, const std::string& args,
                      const std::string& prefix = "");

void write_text(const std::filesystem::path& p, const std::string& text);

// A non-zero exit that is not a timeout, and exactly one line on stderr, "isowall: error: ...",
// that mentions each of `mentions`.
void expect_one_line_error(const RunResult& r, std::initializer_list<std::string> mentions);

// The names in `dir` (hidden ones too), sorted, without the run's stdout.txt and stderr.txt.
std::vector<std::string> files_in(const std::filesystem::path& dir);

}  // namespace isowall::test
