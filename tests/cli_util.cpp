#include "tests/cli_util.h"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace isowall::test {

RunResult run_isowall(const std::filesystem::path& dir, const std::string& args,
                      const std::string& prefix) {
    const auto out = dir / "stdout.txt", err = dir / "stderr.txt";
    const std::string cmd = "cd '" + dir.string() + "' && timeout 120 " + prefix + "'" +
                            std::string(ISOWALL_BINARY) + "' " + args + " > '" + out.string() +
                            "' 2> '" + err.string() + "'";
    const int status = std::system(cmd.c_str());
    RunResult r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

void write_text(const std::filesystem::path& p, const std::string& text) {
    std::ofstream(p) << text;
}

void expect_one_line_error(const RunResult& r, std::initializer_list<std::string> mentions) {
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.exit_code, 124) << "timed out";
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "stderr: " << r.err;
    EXPECT_EQ(r.err.rfind("isowall: error: ", 0), 0u) << "stderr: " << r.err;
    for (const auto& m : mentions)
        EXPECT_NE(r.err.find(m), std::string::npos) << "missing \"" << m << "\" in: " << r.err;
}

std::vector<std::string> files_in(const std::filesystem::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
        const std::string name = e.path().filename();
        if (name != "stdout.txt" && name != "stderr.txt") names.push_back(name);
    }
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace isowall::test
