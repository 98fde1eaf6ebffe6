#include "master/control_window.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "common/core/error.h"
#include "common/core/preview.h"
#include "master/control_view.h"

namespace isowall {
namespace {

// At most one present per display refresh of a common monitor; a change that comes sooner is
// shown by the next due one.
constexpr double kPresentIntervalS = 1.0 / 30;
// Shown again this often even when nothing changed: an X server keeps no copy of a window that
// was covered (no backing store), and Expose events are not handed to us.
constexpr double kRefreshS = 1.0;
// How long the loop sleeps when nothing came: the master costs no CPU while the wall is idle,
// and input is taken within a frame of a 60 Hz display.
constexpr auto kIdleSlice = std::chrono::milliseconds(10);

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

// The first n with no control-NNN.png beside `out`, so a second session does not overwrite the
// first one's snapshots.
int first_free_snapshot(const std::string& out) {
    const auto dir = std::filesystem::path(out).parent_path();
    int n = 1;
    std::error_code ec;
    while (std::filesystem::exists(dir / (snapshot_name(n) + ".png"), ec)) ++n;
    return n;
}

}  // namespace

ControlWindow::ControlWindow(const WallSpec& spec, const std::string& display,
                             const std::string& out)
    : spec_(spec),
      layout_(control_layout(spec)),
      window_(window_options(layout_, display)),
      input_(first_free_snapshot(out)) {
    // The wall's layout at once, so the operator sees the window is theirs while the tiles load.
    window_.present(compose_control(layout_, {}, {"starting the wall", keys_line()}));
}

void ControlWindow::present(const WallMaster& master) {
    std::vector<Image> previews(layout_.tiles.size());
    const auto& by_rank = master.previews();
    for (std::size_t rank = 1; rank < by_rank.size(); ++rank)
        if (by_rank[rank]) {
            const int tile = tile_of_rank(spec_, static_cast<int>(rank));
            previews[static_cast<std::size_t>(tile)] = preview_image(*by_rank[rank]);
        }
    const ControlStatus status{master.iso(),        master.value_min(),  master.value_max(),
                               master.generation(), master.frame_done(), last_};
    window_.present(compose_control(layout_, previews, status_lines(status)));
}

void ControlWindow::note_frame(const WallMaster& master) {
    if (master.generation() != frame_) {
        frame_ = master.generation();
        frame_reported_ = false;
        frame_clock_.restart();
    }
    if (!frame_reported_ && master.frame_done()) {
        frame_reported_ = true;
        // The line a test or an operator's tooling waits for: the wall shows the frame whole.
        std::printf("control: frame %llu done in %.2f s\n", static_cast<unsigned long long>(frame_),
                    frame_clock_.seconds());
        std::fflush(stdout);
    }
}

void ControlWindow::run(WallMaster& master) {
    std::printf(
        "control: window on %s (drag: orbit, wheel: zoom, up/down: iso, s: snapshot, "
        "escape: quit)\n",
        window_.display_name().c_str());
    std::fflush(stdout);
    PresentPacer pacer(kPresentIntervalS);
    Stopwatch clock, since_present;
    std::uint64_t previews_seen = ~std::uint64_t{0}, frame_seen = ~std::uint64_t{0};
    bool done_seen = false;
    for (;;) {
        const ControlState state{master.iso(), master.value_min(), master.value_max(),
                                 layout_.mosaic.width, layout_.mosaic.height};
        const std::vector<std::string> lines = input_.commands(window_.poll(), state);
        for (const std::string& line : lines) {
            std::printf("control: %s\n", line.c_str());
            std::fflush(stdout);
            last_ = line;
            try {
                if (!master.execute(parse_command(line, "control"), "control")) return;
            } catch (const InputError& e) {
                std::printf("isowall: %s\n", e.what());
                std::fflush(stdout);
            }
        }
        master.idle();
        note_frame(master);
        const bool changed = !lines.empty() || master.previews_taken() != previews_seen ||
                             master.generation() != frame_seen || master.frame_done() != done_seen;
        previews_seen = master.previews_taken();
        frame_seen = master.generation();
        done_seen = master.frame_done();
        const double now = clock.seconds();
        if ((changed && pacer.changed(now)) || pacer.due(now) ||
            since_present.seconds() > kRefreshS) {
            present(master);
            pacer.shown(now);
            since_present.restart();
        }
        if (lines.empty()) std::this_thread::sleep_for(kIdleSlice);
    }
}

}  // namespace isowall
