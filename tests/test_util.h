#pragma once
// Helpers shared by the tests: where the shared data lives, temporary folders, reading a file.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace isowall::test {

// ../shared/data beside the source tree (or $ISOWALL_SHARED_DATA); nullopt when absent, so tests
// that need it can GTEST_SKIP() with a message.
std::optional<std::filesystem::path> shared_data_dir();

// Every shared volume at its README isovalues (../shared/data/README.md): 16-bit and 8-bit voxels,
// anisotropic spacing, a heavy noisy surface and a fragmented one.
inline std::vector<std::pair<std::string, double>> shared_isovalues() {
    return {{"tooth", 620},     {"tooth", 1000},    {"cthead", 600},     {"cthead", 1650},
            {"engine", 75},     {"engine", 190},    {"heptane", 50},     {"heptane", 200},
            {"mrhead_t1", 112}, {"mrhead_t1", 490}, {"vhp_ct_head", 40}, {"vhp_ct_head", 105}};
}

// A fresh, empty folder under the build tree for one test's files.
std::filesystem::path scratch_dir(const std::string& name);

// How many times `what` occurs in `text` (e.g. error lines in a log).
std::size_t count_of(const std::string& text, const std::string& what);

// The whole of a text file ("" when it cannot be read).
std::string slurp(const std::filesystem::path& p);

}  // namespace isowall::test
