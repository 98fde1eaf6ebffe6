#include "wall_spec/script.h"

#include <sstream>

#include "core/camera.h"
#include "core/error.h"
#include "core/number.h"
#include "files/input_file.h"

namespace isowall {
namespace {

std::vector<std::string> words_of(std::string_view text) {
    std::istringstream in{std::string(text)};
    std::vector<std::string> words;
    for (std::string w; in >> w;) words.push_back(w);
    return words;
}

// A snapshot's name becomes NAME.png beside the mosaic: one file name, short enough for any file
// system with the extension.
constexpr std::size_t kMaxSnapshotName = 200;

bool plain_name(const std::string& name) {
    if (name.size() > kMaxSnapshotName) return false;
    for (const char ch : name)
        if (ch == '/' || static_cast<unsigned char>(ch) < 0x20 || ch == 0x7F) return false;
    return true;
}

void expect_args(const std::vector<std::string>& w, std::size_t n, const std::string& where,
                 const std::string& usage) {
    if (w.size() != n + 1)
        throw InputError(
            where, w[0],
            "expected \"" + usage + "\", got " + std::to_string(w.size() - 1) + " argument(s)");
}

// `clip PLANE...`, `clip box X0 Y0 Z0 X1 Y1 Z1` or `clip off` (words `w`, w[0] = "clip").
ClipCmd parse_clip(const std::vector<std::string>& w, const std::string& where) {
    const std::string& c = w[0];
    auto num = [&](std::size_t i, const NumberRange& range) {
        return checked_number(w[i], range, where, c);
    };
    const char* usage =
        "expected \"clip PLANE...\" (x<N, y>N, z<N or A,B,C<D, at most 8), \"clip box X0 Y0 "
        "Z0 X1 Y1 Z1\" or \"clip off\"";
    if (w.size() == 2 && w[1] == "off") return ClipCmd{};
    std::string problem;
    if (w.size() >= 2 && w[1] == "box") {
        if (w.size() != 8) throw InputError(where, c, usage);
        const glm::vec3 lo(num(2, limits::kCoordinate), num(3, limits::kCoordinate),
                           num(4, limits::kCoordinate));
        const glm::vec3 hi(num(5, limits::kCoordinate), num(6, limits::kCoordinate),
                           num(7, limits::kCoordinate));
        const auto box = clip_box(lo, hi, problem);
        if (!box) throw InputError(where, c, problem);
        return ClipCmd{*box};
    }
    if (w.size() < 2 || w.size() - 1 > kMaxClipPlanes) throw InputError(where, c, usage);
    ClipCmd cmd;
    for (std::size_t i = 1; i < w.size(); ++i) {
        const auto plane = parse_clip_plane(w[i], problem);
        if (!plane) throw InputError(where, c, problem);
        cmd.clip.add(*plane);
    }
    return cmd;
}

// `iso V`, or `iso V[:COLOUR[:OPACITY]]...`: several surfaces (core/surface_style.h).
IsoCmd parse_iso(const std::vector<std::string>& w, const std::string& where) {
    if (w.size() == 2 && w[1].find(':') == std::string::npos)
        return IsoCmd{checked_number(w[1], limits::kAnyFinite, where, "iso")};
    if (w.size() < 2) expect_args(w, 1, where, "iso V");
    IsoCmd cmd;
    for (std::size_t i = 1; i < w.size(); ++i) {
        std::string problem;
        const auto style = parse_surface_style(w[i], problem);
        if (!style) throw InputError(where, "iso", problem);
        cmd.surfaces.push_back(*style);
    }
    if (std::string problem = surfaces_problem(cmd.surfaces); !problem.empty())
        throw InputError(where, "iso", problem);
    cmd.surfaces = canonical_order(cmd.surfaces);
    cmd.iso = cmd.surfaces[0].iso;
    return cmd;
}

}  // namespace

ScriptCommand parse_command(std::string_view text, const std::string& where) {
    const auto w = words_of(text);
    if (w.empty()) throw InputError(where, "command", "empty command");
    const std::string& c = w[0];
    auto num = [&](std::size_t i, const NumberRange& range) {
        return checked_number(w[i], range, where, c);
    };
    if (c == "orbit") {
        expect_args(w, 2, where, "orbit YAW PITCH");
        return OrbitCmd{num(1, limits::kAngleDeg), num(2, limits::kAngleDeg)};
    }
    if (c == "look-at") {
        expect_args(w, 6, where, "look-at EX EY EZ TX TY TZ");
        auto point = [&](std::size_t i) {
            const auto v = [&](std::size_t k) { return float(num(k, limits::kCoordinate)); };
            return glm::vec3(v(i), v(i + 1), v(i + 2));
        };
        const LookAtCmd cmd{point(1), point(4)};
        if (std::string p = eye_target_problem(cmd.eye, cmd.target); !p.empty())
            throw InputError(where, c, p);
        return cmd;
    }
    if (c == "zoom") {
        expect_args(w, 1, where, "zoom F");
        return ZoomCmd{float(num(1, limits::kZoom))};
    }
    if (c == "pan") {
        expect_args(w, 2, where, "pan DX DY");
        return PanCmd{float(num(1, limits::kPan)), float(num(2, limits::kPan))};
    }
    if (c == "iso") return parse_iso(w, where);
    if (c == "wait") {
        if (w.size() == 2 && w[1] == "done") return WaitCmd{WaitCmd::Until::done, 0};
        if (w.size() == 3 && (w[1] == "rays" || w[1] == "helped"))
            return WaitCmd{w[1] == "rays" ? WaitCmd::Until::rays : WaitCmd::Until::helped,
                           num(2, limits::kRayCount)};
        if (w.size() == 3 && w[1] == "time")
            return WaitCmd{WaitCmd::Until::time, num(2, limits::kWaitSeconds)};
        throw InputError(where, c,
                         "expected \"wait rays N\", \"wait helped N\", \"wait time SECONDS\" or "
                         "\"wait done\"");
    }
    if (c == "snapshot") {
        expect_args(w, 1, where, "snapshot NAME");
        if (!plain_name(w[1]))
            throw InputError(where, c,
                             "expected a plain name (no '/', no control characters, at most " +
                                 std::to_string(kMaxSnapshotName) + " bytes), got " + quote(w[1]));
        return SnapshotCmd{w[1]};
    }
    if (c == "head") {
        expect_args(w, 3, where, "head X Y Z");
        return HeadCmd{{num(1, limits::kHead), num(2, limits::kHead), num(3, limits::kHead)}};
    }
    if (c == "clip") return parse_clip(w, where);
    if (c == "time") {
        expect_args(w, 1, where, "time N");
        // Below volume/time_steps.h's kMaxTimeSteps: the master checks it against the series.
        return TimeCmd{static_cast<std::uint32_t>(num(1, {0, 99999, false, true}))};
    }
    if (c == "play") {
        if (w.size() == 1) return PlayCmd{};
        if (w.size() == 2 && w[1] == "loop") return PlayCmd{true};
        throw InputError(where, c, "expected \"play\" or \"play loop\"");
    }
    if (c == "pause") {
        expect_args(w, 0, where, "pause");
        return PauseCmd{};
    }
    if (c == "quit") {
        expect_args(w, 0, where, "quit");
        return QuitCmd{};
    }
    throw InputError(
        where, "command",
        "unknown command " + quote(c) +
            " (expected orbit, look-at, zoom, pan, iso, head, clip, wait, snapshot or quit)");
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

std::vector<ScriptLine> load_script(const std::filesystem::path& path) {
    return parse_script(read_input_file(path, "--script", kMaxScriptBytes), path.string());
}

}  // namespace isowall

namespace isowall {

bool apply_camera_command(const ScriptCommand& cmd, Camera& camera, float aspect) {
    if (const auto* c = std::get_if<OrbitCmd>(&cmd)) {
        camera = orbit(camera, c->yaw_deg, c->pitch_deg);
    } else if (const auto* c = std::get_if<LookAtCmd>(&cmd)) {
        camera.eye = c->eye;
        camera.target = c->target;
    } else if (const auto* c = std::get_if<ZoomCmd>(&cmd)) {
        camera = zoom(camera, c->factor);
    } else if (const auto* c = std::get_if<PanCmd>(&cmd)) {
        camera = pan(camera, c->dx, c->dy, aspect);
    } else {
        return false;
    }
    return true;
}

}  // namespace isowall
