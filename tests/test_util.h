#pragma once
// Helpers shared by the tests: where the shared data lives, temporary folders.
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

}  // namespace isowall::test
