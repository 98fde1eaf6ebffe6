// The replay test: a main (not libFuzzer's) that runs every file of the folders it is given
// through the harness's LLVMFuzzerTestOneInput, so the seed corpus and every crash the fuzzers
// found stay tests of the normal build (gcc, and ASan+UBSan in CI). A finding aborts the process,
// so CTest reports the failure; the file being run is printed first, so its name is in the log.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/fuzz_check.h"

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputs_in(const fs::path& where) {
    std::vector<fs::path> files;
    if (fs::is_regular_file(where)) return {where};
    if (!fs::is_directory(where)) return files;
    for (const auto& e : fs::recursive_directory_iterator(where))
        if (e.is_regular_file() && e.path().filename() != "README.md") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
}

std::vector<std::uint8_t> read_all(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

// replay FOLDER_OR_FILE... : runs each input once. Fails when no input was found at all, so a
// moved corpus cannot turn the test into one that checks nothing.
int main(int argc, char** argv) {
    std::size_t count = 0;
    for (int i = 1; i < argc; ++i)
        for (const fs::path& file : inputs_in(argv[i])) {
            std::fprintf(stderr, "replay: %s\n", file.c_str());
            const std::vector<std::uint8_t> bytes = read_all(file);
            LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
            ++count;
        }
    std::printf("replay: %zu input(s) ran clean\n", count);
    if (count == 0) {
        std::fprintf(stderr, "replay: no inputs found\n");
        return 1;
    }
    return 0;
}
