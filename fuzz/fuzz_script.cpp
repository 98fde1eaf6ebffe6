// Harness: wall script lines (wall_spec/script.cpp), both entry points: parse_script for a
// script file and parse_command for one console line. A command that parses must be one the
// master can apply as is: finite numbers (a float cast of 1e300 is infinity, of 1e-50 zero), a
// positive zoom, a non-negative wait and a plain snapshot name.
#include <cmath>
#include <string>
#include <type_traits>
#include <variant>

#include "core/error.h"
#include "fuzz/fuzz_check.h"
#include "wall_spec/script.h"

namespace {

using isowall::fuzz::check;

bool finite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void check_command(const isowall::ScriptCommand& command) {
    std::visit(
        [](const auto& c) {
            using T = std::decay_t<decltype(c)>;
            if constexpr (std::is_same_v<T, isowall::OrbitCmd>) {
                check(std::isfinite(c.yaw_deg) && std::isfinite(c.pitch_deg), "orbit: finite");
            } else if constexpr (std::is_same_v<T, isowall::LookAtCmd>) {
                check(finite(c.eye) && finite(c.target), "look-at: finite");
            } else if constexpr (std::is_same_v<T, isowall::ZoomCmd>) {
                check(std::isfinite(c.factor) && c.factor > 0, "zoom: finite and > 0");
            } else if constexpr (std::is_same_v<T, isowall::PanCmd>) {
                check(std::isfinite(c.dx) && std::isfinite(c.dy), "pan: finite");
            } else if constexpr (std::is_same_v<T, isowall::IsoCmd>) {
                check(std::isfinite(c.iso), "iso: finite");
            } else if constexpr (std::is_same_v<T, isowall::WaitCmd>) {
                check(std::isfinite(c.amount) && c.amount >= 0, "wait: finite and >= 0");
            } else if constexpr (std::is_same_v<T, isowall::SnapshotCmd>) {
                check(!c.name.empty() && c.name.find('/') == std::string::npos,
                      "snapshot: a plain name");
                for (const char ch : c.name)
                    check(static_cast<unsigned char>(ch) >= 0x20 && ch != 0x7f,
                          "snapshot: a name without control characters");
            }
        },
        command);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text = isowall::fuzz::as_text(data, size);
    try {
        for (const isowall::ScriptLine& line : isowall::parse_script(text, "fuzz.txt"))
            check_command(line.command);
    } catch (const isowall::InputError&) {
    }
    // The console hands one line at a time, comments and all.
    try {
        check_command(isowall::parse_command(text.substr(0, text.find('\n')), "console"));
    } catch (const isowall::InputError&) {
    }
    return 0;
}
