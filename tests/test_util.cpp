#include "tests/test_util.h"

#include <cstdlib>
#include <fstream>
#include <iterator>

namespace isowall::test {

std::optional<std::filesystem::path> shared_data_dir() {
    namespace fs = std::filesystem;
    if (const char* env = std::getenv("ISOWALL_SHARED_DATA")) {
        if (fs::is_directory(env)) return fs::path(env);
    }
    const fs::path beside = fs::path(ISOWALL_SOURCE_DIR).parent_path() / "shared" / "data";
    if (fs::is_directory(beside)) return beside;
    return std::nullopt;
}

std::filesystem::path scratch_dir(const std::string& name) {
    namespace fs = std::filesystem;
    fs::path dir = fs::current_path() / "scratch" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::size_t count_of(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace isowall::test
