#pragma once
// Previews for the control window (--control): what a tile shows, made small enough to travel
// often, and turned back into an image on the master.
#include <cstdint>
#include <vector>

#include "core/image.h"

namespace isowall {

// Largest side of a preview: a whole wall fits in a control window of 1024x768
// (wall_spec/control_layout.h), so a tile never needs more.
inline constexpr int kMaxPreviewSide = 1024;

// What a tile shows, small: RGB, not RGBA (a preview is only looked at). It travels to the master
// as wall_protocol/protocol.h's PreviewMsg.
struct Preview {
    std::uint64_t generation = 0;            // of the view the tile shows
    std::int32_t width = 1, height = 1;      // 1..kMaxPreviewSide each
    std::vector<std::uint8_t> rgb{0, 0, 0};  // width * height * 3, row 0 at the top
};

// `shown` (the tile's frame as it is now, RGBA) shrunk by the box filter of shrink_box, by the
// smallest integer factor that brings its larger side to at most `max_side` (clamped to
// 1..kMaxPreviewSide; wall_spec/control_layout.h: preview_max_side gives the size a tile takes
// in the control window), as RGB. An empty `shown` gives one black pixel.
Preview make_preview(const Image& shown, std::uint64_t generation, int max_side);

// The preview as an RGBA image (alpha 255, no depth).
Image preview_image(const Preview& preview);

}  // namespace isowall
