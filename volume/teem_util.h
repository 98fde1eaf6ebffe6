#pragma once
// Teem glue shared by the NRRD loader and writer (private to isowall_volume).
#include <teem/nrrd.h>

#include <cstdlib>
#include <sstream>
#include <string>

namespace isowall::teem {

// Teem reports a stack of messages, outermost first; the innermost one says what was wrong.
inline std::string error() {
    char* raw = biffGetDone(NRRD);
    std::string all = raw ? raw : "unknown error";
    std::free(raw);
    std::string last;
    std::istringstream lines(all);
    for (std::string line; std::getline(lines, line);)
        if (!line.empty()) last = line;
    // Drop the "[nrrd] function: " prefix.
    if (auto p = last.find("] "); p != std::string::npos) last = last.substr(p + 2);
    if (auto p = last.find(": "); p != std::string::npos && p < 40) last = last.substr(p + 2);
    return last;
}

struct NrrdDeleter {
    void operator()(Nrrd* n) const { nrrdNuke(n); }
};
struct NioDeleter {
    void operator()(NrrdIoState* n) const { nrrdIoStateNix(n); }
};

}  // namespace isowall::teem
