#include "master/control_window.h"

#include <cstdio>

#include "core/error.h"
#include "master/control_view.h"

namespace isowall {
namespace {

// At most one present per display refresh of a common monitor; a change that comes sooner is
// shown by the next due one.
constexpr double kPresentIntervalS = 1.0 / 30;
// Shown again this often even when nothing changed: an X server keeps no copy of a window that
// was covered (no backing store), and Expose events are not handed to us.
constexpr double kRefreshS = 1.0;

WindowOptions window_options(const ControlLayout& layout, const std::string& display) {
    const PixelSize size = control_window_size(layout);
    WindowOptions o;
    o.display = display;
    o.title = kControlTitle;
    o.width = size.width;
    o.height = size.height;
    o.input = true;
    return o;
}

}  // namespace

ControlWindow::ControlWindow(const WallSpec& spec, const std::string& display,
                             const std::string& out)
    : layout_(control_layout(spec)),
      window_(window_options(layout_, display)),
      input_(first_free_snapshot(out)),
      pacer_(kPresentIntervalS) {
    // The wall's layout at once, so the operator sees the window is theirs while the tiles load.
    window_.present(compose_control(layout_, {}, {"starting the wall", keys_line()}));
}

void ControlWindow::present(const WallMaster& master) {
    ControlStatus status{master.iso(),        master.value_min(),  master.value_max(),
                         master.generation(), master.frame_done(), last_};
    status.clip = clip_text(master.clip());
    if (const std::size_t n = master.options().steps; n > 0)
        status.time = "time " + std::to_string(master.step()) + "/" + std::to_string(n) +
                      (master.playing() ? " playing" : "");
    if (const auto& s = master.surfaces(); !one_plain_surface(s))
        for (const SurfaceStyle& one : s) {
            if (!status.surfaces.empty()) status.surfaces += ' ';
            status.surfaces += surface_style_text(one);
        }
    window_.present(compose_control(layout_, tile_previews(master), status_lines(status)));
}

void ControlWindow::begin() {
    std::printf(
        "control: window on %s (drag: orbit, wheel: zoom, up/down: iso, c and [ ]: clip, "
        "comma/period: time step, p: play, s: snapshot, escape: quit)\n",
        window_.display_name().c_str());
    std::fflush(stdout);
}

std::vector<SteeringLine> ControlWindow::take(const WallMaster& master) {
    const ControlState state{master.iso(),
                             master.value_min(),
                             master.value_max(),
                             layout_.mosaic.width,
                             layout_.mosaic.height,
                             master.head(),
                             master.spec().physical ? kHeadStepMm : kHeadStepWidths,
                             master.clip(),
                             master.dims(),
                             std::uint32_t(master.options().steps),
                             master.step(),
                             master.playing()};
    std::vector<SteeringLine> lines;
    for (std::string& text : input_.commands(window_.poll(), state))
        lines.push_back({std::move(text), "control"});
    return lines;
}

void ControlWindow::ran(const SteeringLine& line, const std::string& error) {
    if (error.empty()) last_ = line.who == "control" ? line.text : line.who + ": " + line.text;
}

void ControlWindow::show(const WallMaster& master, const FrameNote&, bool changed) {
    const double now = clock_.seconds();
    if ((changed && pacer_.changed(now)) || pacer_.due(now) ||
        since_present_.seconds() > kRefreshS) {
        present(master);
        pacer_.shown(now);
        since_present_.restart();
    }
}

void ControlWindow::run(WallMaster& master) {
    run_steering(master, {this}, "control");
}

}  // namespace isowall
