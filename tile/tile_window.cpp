#include "tile/tile_window.h"

#include <stdexcept>

namespace isowall {

std::string tile_window_title(int tile, Eye eye) {
    std::string title = "isowall tile " + std::to_string(tile);
    if (eye != Eye::centre) title.append(" ").append(to_string(eye));
    return title;
}

TileWindow::TileWindow(const std::string& display, int tile, const std::string& host,
                       WindowOptions::Part part, Eye eye) {
    WindowOptions o;
    o.display = display;
    o.title = tile_window_title(tile, eye);
    o.fullscreen = true;
    o.part = part;
    try {
        window_ = std::make_unique<XWindow>(o);
    } catch (const DisplayError& e) {
        throw std::runtime_error("on host " + host + ": --windows: " + e.what());
    }
}

void TileWindow::show(const Image& tile, std::uint64_t) {
    window_->present(tile);
    ++presents_;
}

}  // namespace isowall
