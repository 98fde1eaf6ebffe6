#pragma once
// Where a tile shows its frame while it builds, besides the image the master gathers at quit: a
// window on the tile's display (tile/tile_window.h, through display/), a scaled-down preview
// for the master's control window. The tile loop calls show() with what the tile shows now, at
// most once per interval_s(), and once more with the last change when its work runs out, so the
// final frame is always shown. Implementations need no GL and take no locks of the tile loop.
#include <cstdint>

#include "core/image.h"

namespace isowall {

class FrameShow {
  public:
    virtual ~FrameShow() = default;
    // The shortest time between two shows (a display refresh for a window).
    virtual double interval_s() const = 0;
    // `tile` is the tile's frame (colour and depth) of view `generation`.
    virtual void show(const Image& tile, std::uint64_t generation) = 0;
};

}  // namespace isowall
