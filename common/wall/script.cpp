#include "common/wall/script.h"

#include <cmath>
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
    if (c == "orbit") {
        expect_args(w, 2, where, "orbit YAW PITCH");
        return OrbitCmd{float(num(1)), float(num(2))};
    }
    if (c == "look-at") {
        expect_args(w, 6, where, "look-at EX EY EZ TX TY TZ");
        return LookAtCmd{{float(num(1)), float(num(2)), float(num(3))},
                         {float(num(4)), float(num(5)), float(num(6))}};
    }
    if (c == "zoom") {
        expect_args(w, 1, where, "zoom F");
        const double f = num(1);
        if (f <= 0) throw InputError(where, c, "expected a positive factor, got " + w[1]);
        return ZoomCmd{float(f)};
    }
    if (c == "pan") {
        expect_args(w, 2, where, "pan DX DY");
        return PanCmd{float(num(1)), float(num(2))};
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
        if (w[1].find('/') != std::string::npos)
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
