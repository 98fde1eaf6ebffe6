#include "common/wall/script.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "common/core/error.h"

namespace isowall {
namespace {

std::vector<std::string> words_of(std::string_view text) {
    std::istringstream in{std::string(text)};
    std::vector<std::string> words;
    for (std::string w; in >> w;) words.push_back(w);
    return words;
}

double number(const std::string& word, const std::string& where, const std::string& command) {
    std::size_t used = 0;
    double v = 0;
    try {
        v = std::stod(word, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != word.size() || !std::isfinite(v))
        throw InputError(where, command, "expected a number, got \"" + word + "\"");
    return v;
}

// Camera commands hold floats: a double beyond float range would become an infinite float (found
// by fuzz/fuzz_script.cpp), so the range is checked before the cast.
float float_number(const std::string& word, const std::string& where, const std::string& command) {
    const double v = number(word, where, command);
    if (std::abs(v) > std::numeric_limits<float>::max())
        throw InputError(where, command, "expected a number within float range, got " + word);
    return static_cast<float>(v);
}

// A snapshot name becomes a file name: no folders, and no control characters (a NUL would cut
// the name short, so the snapshot would land in another file).
bool plain_name(const std::string& name) {
    for (const char ch : name)
        if (ch == '/' || static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) return false;
    return true;
}

void expect_args(const std::vector<std::string>& w, std::size_t n, const std::string& where,
                 const std::string& usage) {
    if (w.size() != n + 1)
        throw InputError(
            where, w[0],
            "expected \"" + usage + "\", got " + std::to_string(w.size() - 1) + " argument(s)");
}

}  // namespace

ScriptCommand parse_command(std::string_view text, const std::string& where) {
    const auto w = words_of(text);
    if (w.empty()) throw InputError(where, "command", "empty command");
    const std::string& c = w[0];
    auto num = [&](std::size_t i) { return number(w[i], where, c); };
    auto fnum = [&](std::size_t i) { return float_number(w[i], where, c); };
    if (c == "orbit") {
        expect_args(w, 2, where, "orbit YAW PITCH");
        return OrbitCmd{fnum(1), fnum(2)};
    }
    if (c == "look-at") {
        expect_args(w, 6, where, "look-at EX EY EZ TX TY TZ");
        return LookAtCmd{{fnum(1), fnum(2), fnum(3)}, {fnum(4), fnum(5), fnum(6)}};
    }
    if (c == "zoom") {
        expect_args(w, 1, where, "zoom F");
        // A factor below float's smallest would be zero as a float.
        const float f = fnum(1);
        if (!(f > 0)) throw InputError(where, c, "expected a positive factor, got " + w[1]);
        return ZoomCmd{f};
    }
    if (c == "pan") {
        expect_args(w, 2, where, "pan DX DY");
        return PanCmd{fnum(1), fnum(2)};
    }
    if (c == "iso") {
        expect_args(w, 1, where, "iso V");
        return IsoCmd{num(1)};
    }
    if (c == "wait") {
        if (w.size() == 2 && w[1] == "done") return WaitCmd{WaitCmd::Until::done, 0};
        if (w.size() == 3 && (w[1] == "rays" || w[1] == "time")) {
            const double a = num(2);
            if (a < 0) throw InputError(where, c, "expected a non-negative amount, got " + w[2]);
            return WaitCmd{w[1] == "rays" ? WaitCmd::Until::rays : WaitCmd::Until::time, a};
        }
        throw InputError(where, c,
                         "expected \"wait rays N\", \"wait time SECONDS\" or \"wait done\"");
    }
    if (c == "snapshot") {
        expect_args(w, 1, where, "snapshot NAME");
        if (!plain_name(w[1]))
            throw InputError(where, c, "expected a plain name, got \"" + w[1] + "\"");
        return SnapshotCmd{w[1]};
    }
    if (c == "quit") {
        expect_args(w, 0, where, "quit");
        return QuitCmd{};
    }
    throw InputError(where, "command",
                     "unknown command \"" + c +
                         "\" (expected orbit, look-at, zoom, pan, iso, wait, snapshot or quit)");
}

std::vector<ScriptLine> parse_script(std::string_view text, const std::string& file) {
    std::vector<ScriptLine> lines;
    int n = 0;
    std::size_t pos = 0;
    while (pos <= text.size()) {
        const std::size_t end = std::min(text.find('\n', pos), text.size());
        std::string_view line = text.substr(pos, end - pos);
        ++n;
        if (const auto hash = line.find('#'); hash != std::string_view::npos)
            line = line.substr(0, hash);
        if (line.find_first_not_of(" \t\r") != std::string_view::npos)
            lines.push_back({n, parse_command(line, file + ":" + std::to_string(n))});
        if (end == text.size()) break;
        pos = end + 1;
    }
    return lines;
}

}  // namespace isowall
