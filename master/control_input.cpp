#include "master/control_input.h"

#include <filesystem>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include "wall_spec/script.h"

namespace isowall {
namespace {

// %g of a number that is a sum of small steps: no "-0".
std::string number(double v, int digits = 6) {
    char buf[40];
    std::snprintf(buf, sizeof(buf), "%.*g", digits, v + 0.0);
    return buf;
}

// How many isovalue steps a key is worth (0: not an isovalue key).
double iso_steps_of(const std::string& key) {
    if (key == "Up" || key == "plus" || key == "KP_Add" || key == "equal") return 1;
    if (key == "Down" || key == "minus" || key == "KP_Subtract") return -1;
    if (key == "Page_Up" || key == "Prior") return 10;
    if (key == "Page_Down" || key == "Next") return -10;
    return 0;
}

}  // namespace

std::string snapshot_name(int n, std::string_view prefix) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "-%03d", n);
    return std::string(prefix) + buf;
}

int first_free_snapshot(const std::string& out, int from, std::string_view prefix) {
    const auto dir = std::filesystem::path(out).parent_path();
    std::error_code ec;
    int n = from;
    while (std::filesystem::exists(dir / (snapshot_name(n, prefix) + ".png"), ec)) ++n;
    return n;
}

std::string head_line(const glm::dvec3& head) {
    return "head " + number(head.x) + " " + number(head.y) + " " + number(head.z);
}

std::string iso_line(double iso, double lo, double hi) {
    for (int digits : {6, 9, 17}) {
        const std::string v = number(iso, digits);
        const double back = std::strtod(v.c_str(), nullptr);
        if ((back >= lo && back <= hi) || digits == 17) return "iso " + v;
    }
    return "iso " + number(iso, 17);  // not reached
}

namespace {

// The axis a plane cuts across (its normal along it), or -1.
int axis_of(const ClipPlane& p) {
    for (int a = 0; a < 3; ++a) {
        glm::vec3 axis{0};
        axis[a] = 1;
        if (p.normal == axis || p.normal == -axis) return a;
    }
    return -1;
}

std::string axis_clip_line(int axis, bool below, double at) {
    return std::string("clip ") + char('x' + axis) + (below ? "<" : ">") + number(at);
}

}  // namespace

std::string clip_cycle_line(const ClipSet& now, glm::ivec3 dims) {
    const int axis = now.count == 1 ? axis_of(now.planes[0]) : -1;
    if (!now.empty() && (axis < 0 || axis == 2)) return "clip off";
    const int next = now.empty() ? 0 : axis + 1;
    return axis_clip_line(next, true, std::floor(0.5 * double(dims[next] - 1)));
}

std::string clip_move_line(const ClipSet& now, glm::ivec3 dims, int steps) {
    const int axis = now.count == 1 ? axis_of(now.planes[0]) : -1;
    if (axis < 0 || steps == 0) return "";
    const ClipPlane& p = now.planes[0];
    const double side = double(dims[axis] - 1);
    const double at = double(p.normal[axis]) * double(p.at);  // where the plane crosses the axis
    const double moved = std::clamp(at + steps * kClipStep * side, 0.0, side);
    if (moved == at) return "";
    return axis_clip_line(axis, p.normal[axis] < 0, moved);
}

void ControlInput::add_clip(const std::string& line, std::vector<std::string>& out) {
    out.push_back(line);
    state_.clip = std::get<ClipCmd>(parse_command(line, "control")).clip;
}

void ControlInput::accumulate(Pending kind, std::vector<std::string>& out) {
    if (pending_ != kind) flush(out);
    pending_ = kind;
}

void ControlInput::flush(std::vector<std::string>& out) {
    const Pending kind = std::exchange(pending_, Pending::none);
    if (kind == Pending::orbit && (drag_x_ != 0 || drag_y_ != 0)) {
        out.push_back("orbit " + number(-drag_x_ * kOrbitDegPerPx) + " " +
                      number(-drag_y_ * kOrbitDegPerPx));
    } else if (kind == Pending::pan && (drag_x_ != 0 || drag_y_ != 0)) {
        out.push_back("pan " + number(-drag_x_ / std::max(state_.mosaic_width, 1)) + " " +
                      number(drag_y_ / std::max(state_.mosaic_height, 1)));
    } else if (kind == Pending::zoom && zoom_steps_ != 0) {
        out.push_back("zoom " + number(std::pow(kZoomStep, zoom_steps_)));
    } else if (kind == Pending::iso && iso_steps_ != 0) {
        const double range = state_.value_max - state_.value_min;
        const double iso = std::clamp(state_.iso + iso_steps_ * kIsoStep * range, state_.value_min,
                                      state_.value_max);
        if (iso != state_.iso) {
            out.push_back(iso_line(iso, state_.value_min, state_.value_max));
            // The next iso key of this poll starts from the value just asked for.
            state_.iso = std::strtod(out.back().c_str() + 4, nullptr);
        }
    } else if (kind == Pending::head && head_steps_ != 0) {
        state_.head.x += head_steps_ * state_.head_step;
        out.push_back(head_line(state_.head));
    } else if (kind == Pending::clip) {
        if (const std::string line = clip_move_line(state_.clip, state_.dims, clip_steps_);
            !line.empty())
            add_clip(line, out);
    }
    drag_x_ = drag_y_ = 0;
    zoom_steps_ = 0;
    iso_steps_ = 0;
    head_steps_ = 0;
    clip_steps_ = 0;
}

std::string time_key_line(const std::string& key, const ControlState& state) {
    if (state.steps == 0) return {};
    if (key == "p" || key == "P") return state.playing ? "pause" : "play loop";
    if (key == "comma" && state.step > 0) return "time " + std::to_string(state.step - 1);
    if (key == "period" && state.step + 1 < state.steps)
        return "time " + std::to_string(state.step + 1);
    return {};
}

void ControlInput::drag_to(int x, int y) {
    if (left_down_ || right_down_) {
        drag_x_ += x - last_x_;
        drag_y_ += y - last_y_;
    }
    last_x_ = x;
    last_y_ = y;
}

void ControlInput::key(const std::string& name, std::vector<std::string>& out) {
    if (const double steps = iso_steps_of(name); steps != 0) {
        accumulate(Pending::iso, out);
        iso_steps_ += steps;
    } else if ((name == "Left" || name == "Right") && state_.head_step > 0) {
        accumulate(Pending::head, out);
        head_steps_ += name == "Right" ? 1 : -1;
    } else if (name == "Home" && state_.head_step > 0) {
        flush(out);
        state_.head = glm::dvec3(0);
        out.push_back(head_line(state_.head));
    } else if ((name == "c" || name == "C") && state_.dims.x > 0) {
        flush(out);
        add_clip(clip_cycle_line(state_.clip, state_.dims), out);
    } else if ((name == "bracketleft" || name == "bracketright") && state_.dims.x > 0) {
        accumulate(Pending::clip, out);
        clip_steps_ += name == "bracketright" ? 1 : -1;
    } else if (std::string line = time_key_line(name, state_); !line.empty()) {
        flush(out);
        out.push_back(line);
        // The poll's next keys see what this one asked for.
        if (line.starts_with("time ")) state_.step = std::uint32_t(std::stoul(line.substr(5)));
        state_.playing = line.starts_with("play");
    } else if (name == "s" || name == "S") {
        flush(out);
        out.push_back("snapshot " + snapshot_name(next_snapshot_++));
    } else if (name == "Escape") {
        flush(out);
        out.push_back("quit");
        quit_ = true;
    }
}

std::vector<std::string> ControlInput::commands(const std::vector<WindowEvent>& events,
                                                const ControlState& state) {
    std::vector<std::string> out;
    state_ = state;
    pending_ = Pending::none;
    quit_ = false;
    for (const WindowEvent& e : events) {
        if (quit_) break;
        using Kind = WindowEvent::Kind;
        if (e.kind == Kind::motion ||
            (e.kind == Kind::release && (e.button == 1 || e.button == 3))) {
            if (left_down_ || right_down_)
                accumulate(left_down_ ? Pending::orbit : Pending::pan, out);
            drag_to(e.x, e.y);
            if (e.kind == Kind::release) (e.button == 1 ? left_down_ : right_down_) = false;
        } else if (e.kind == Kind::press && (e.button == 1 || e.button == 3)) {
            // A drag starts here; one with the other button held goes on as it was.
            if (!left_down_ && !right_down_) {
                last_x_ = e.x;
                last_y_ = e.y;
            }
            (e.button == 1 ? left_down_ : right_down_) = true;
        } else if (e.kind == Kind::press && (e.button == 4 || e.button == 5)) {
            accumulate(Pending::zoom, out);
            zoom_steps_ += e.button == 4 ? 1 : -1;
        } else if (e.kind == Kind::key) {
            key(e.key, out);
        } else if (e.kind == Kind::close) {
            flush(out);
            out.push_back("quit");
            quit_ = true;
        }
    }
    flush(out);
    return out;
}

}  // namespace isowall
