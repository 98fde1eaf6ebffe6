#pragma once
// Helpers shared by the tests: where the shared data lives, temporary folders.
#include <filesystem>
#include <optional>
#include <string>

namespace isowall::test {

// ../shared/data beside the source tree (or $ISOWALL_SHARED_DATA); nullopt when absent, so tests
// that need it can GTEST_SKIP() with a message.
std::optional<std::filesystem::path> shared_data_dir();

// A fresh, empty folder under the build tree for one test's files.
std::filesystem::path scratch_dir(const std::string& name);

}  // namespace isowall::test
