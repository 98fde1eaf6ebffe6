// Parsing the program's command line in process, for the tests of its options.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "app/program_cli.h"

namespace isowall::test {

// The error CLI11 reports for `args` (split on spaces), or "" when they parse into `cli`.
inline std::string parse_error(ProgramCli& cli, const std::string& args) {
    std::vector<std::string> words{"isowall"};
    std::istringstream in(args);
    for (std::string w; in >> w;) words.push_back(w);
    std::vector<const char*> argv;
    for (const std::string& w : words) argv.push_back(w.c_str());
    try {
        cli.app.parse(static_cast<int>(argv.size()), argv.data());
        return "";
    } catch (const CLI::ParseError& e) {
        return e.what();
    }
}

// The same into a fresh command line.
inline std::string parse_error(const std::string& args) {
    ProgramCli cli;
    return parse_error(cli, args);
}

}  // namespace isowall::test
