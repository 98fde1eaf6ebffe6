#pragma once
// Helpers shared by the tests: where the shared data lives, temporary folders, reading a file.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

namespace isowall::test {

// ../shared/data beside the source tree (or $ISOWALL_SHARED_DATA); nullopt when absent, so tests
// that need it can GTEST_SKIP() with a message.
std::optional<std::filesystem::path> shared_data_dir();

// A fresh, empty folder under the build tree for one test's files.
std::filesystem::path scratch_dir(const std::string& name);

// How many times `what` occurs in `text` (e.g. error lines in a log).
std::size_t count_of(const std::string& text, const std::string& what);

// The whole of a text file ("" when it cannot be read).
std::string slurp(const std::filesystem::path& p);

}  // namespace isowall::test
