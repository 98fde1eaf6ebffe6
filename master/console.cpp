#include "master/console.h"

#include <cstdio>

#include "common/core/error.h"

namespace isowall {

void run_console(
    std::istream& in,
    const std::function<bool(const ScriptCommand&, const std::string& where)>& execute) {
    std::printf("console: orbit, look-at, zoom, pan, iso, wait, snapshot, quit\n> ");
    std::fflush(stdout);
    int line = 0;
    for (std::string text; std::getline(in, text);) {
        ++line;
        if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
        try {
            if (!execute(parse_command(text, "console:" + std::to_string(line)), "console")) break;
        } catch (const InputError& e) {
            std::printf("isowall: %s\n", e.what());
        }
        std::printf("> ");
        std::fflush(stdout);
    }
}

}  // namespace isowall
