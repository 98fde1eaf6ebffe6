// Running the isowall program from a test (under mpirun or alone), shared by the tests that do.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/test_util.h"

namespace isowall::test {

// Runs a command under `timeout` (the test guards against hangs itself) and returns its exit code.
inline int run(const std::string& cmd, const std::filesystem::path& log, int guard_s = 120) {
    const std::string full = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 timeout " +
                             std::to_string(guard_s) + " " + cmd + " > '" + log.string() + "' 2>&1";
    const int status = std::system(full.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The binary, quoted. Built step by step: GCC 12 warns falsely (-Wrestrict) on "literal" + string.
inline std::string isowall_cmd() {
    std::string s = "'";
    s += ISOWALL_BINARY;
    s += "' ";
    return s;
}

inline std::string mpirun(int np, const std::string& options = "") {
    std::string s = "mpirun " + options + "--oversubscribe -np ";
    s += std::to_string(np);
    s += ' ';
    return s + isowall_cmd();
}

}  // namespace isowall::test
