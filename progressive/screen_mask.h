#pragma once
// The screen mask ("empty space costs nothing"): the pixels of a region whose ray may
// meet a box where the surface can be (the active nodes of a coarse octree level). It generalises
// the volume's screen box from one box to many: each box covers the pixel rectangle screen_box()
// gives it (its 8 corners projected, one pixel of margin, the whole screen for a box crossing the
// eye plane), so a pixel left out cannot see any of the boxes, and a ray there needs no casting.
#include <cstddef>
#include <cstdint>
#include <ostream>
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/box.h"
#include "core/camera.h"

namespace isowall {

struct ScreenMask {
    PixelRect rect;                  // the bounding box of the pixels to cast (empty: none)
    std::vector<std::uint8_t> cast;  // rect-local, row-major: != 0 where the ray is to be cast
    std::size_t count = 0;           // pixels to cast
};

// The mask of `region` (clipped to the width x height screen) for `boxes` (object space) seen
// through `view` (object -> view space) and `frustum`. Rasterised by a sweep over the rows of the
// rectangles' bounding box, so it costs one pass over the boxes plus one over that box, however
// large or overlapping the rectangles are.
ScreenMask screen_mask(std::span<const Box3> boxes, const glm::mat4& view, const Frustum& frustum,
                       int width, int height, PixelRect region);

inline std::ostream& operator<<(std::ostream& os, const ScreenMask& m) {
    return os << "ScreenMask{rect=" << m.rect.x << "," << m.rect.y << " " << m.rect.width << "x"
              << m.rect.height << " count=" << m.count << "}";
}

}  // namespace isowall
