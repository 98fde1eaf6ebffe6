#pragma once
// Previews for the control window (--control): what a tile shows, made small enough to travel
// often, and turned back into an image on the master.
#include <cstdint>

#include "comm/protocol.h"
#include "common/core/image.h"

namespace isowall {

// `shown` (the tile's frame as it is now, RGBA) shrunk by the box filter of shrink_box, by the
// smallest integer factor that brings its larger side to at most `max_side` (clamped to
// 1..kMaxPreviewSide; common/wall/control_layout.h: preview_max_side gives the size a tile takes
// in the control window), as RGB. An empty `shown` gives one black pixel.
PreviewMsg make_preview(const Image& shown, std::uint64_t generation, int max_side);

// The preview as an RGBA image (alpha 255, no depth).
Image preview_image(const PreviewMsg& preview);

}  // namespace isowall
