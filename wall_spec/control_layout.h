#pragma once
// Where the control window (isowall wall --control) shows each tile: the whole virtual screen,
// bezels included, scaled down to fit the window, so the operator sees the wall as it stands.
// Pure geometry: the master draws with it, and a tile sizes its previews by it.
#include <ostream>
#include <vector>

#include "wall_spec/wall.h"

namespace isowall {

// The largest mosaic a control window shows (a laptop's screen leaves room for it).
inline constexpr PixelSize kControlMaxSize{1024, 768};

struct ControlLayout {
    PixelSize mosaic;  // the virtual screen scaled by `scale`, at least 1x1
    double scale = 1;  // mosaic pixels per virtual-screen pixel: at most 1, never enlarged
    // By tile index: where the tile lands in the mosaic. Neighbours share their edge exactly
    // (both ends are scaled and floored), so a seamless wall shows no seam and a bezel keeps its
    // scaled width. A disabled tile's rect is empty.
    std::vector<PixelRect> tiles;
};

// The virtual screen of `spec` fitted into `max` (each side at least 1), keeping its aspect.
ControlLayout control_layout(const WallSpec& spec, PixelSize max = kControlMaxSize);

// The larger side of the largest tile in control_layout(spec, max), at least 1: the size a tile's
// preview needs (core/preview.h: make_preview's max_side).
int preview_max_side(const WallSpec& spec, PixelSize max = kControlMaxSize);

std::ostream& operator<<(std::ostream& os, const ControlLayout& layout);

}  // namespace isowall
