#include "tile/tile_window.h"

#include <stdexcept>

namespace isowall {

std::string tile_window_title(int tile) {
    return "isowall tile " + std::to_string(tile);
}

TileWindow::TileWindow(const std::string& display, int tile, const std::string& host) {
    WindowOptions o;
    o.display = display;
    o.title = tile_window_title(tile);
    o.fullscreen = true;
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
