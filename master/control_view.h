#pragma once
// The picture in the control window (isowall wall --control): the wall as a live mosaic of the
// tiles' previews, bezels in grey, and a status bar with the isovalue, the frame and the keys.
// Pure: composed from values, so it is tested without a display.
#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "master/control_text.h"
#include "wall_spec/control_layout.h"

namespace isowall {

// Grey enough to tell apart from a black background and from a dark surface.
inline constexpr Rgb kControlBezel{96, 96, 96};
inline constexpr Rgb kControlStatusBackground{24, 24, 24};
inline constexpr Rgb kControlStatusText{230, 230, 230};
inline constexpr int kControlTextScale = 2;
// Two lines of text under the mosaic.
inline constexpr int kControlStatusHeight = 2 * (kGlyphHeight + 2) * kControlTextScale + 4;

// What the status bar says.
struct ControlStatus {
    double iso = 0, value_min = 0, value_max = 0;
    std::uint64_t frame = 0;  // the master's generation
    bool done = false;        // every tile has finished the frame
    std::string last;         // the last command the window gave, e.g. "orbit -30 0"
    std::string clip{};       // the view's clip planes as a script writes them, or empty
    // Several surfaces (or one coloured or translucent), as `iso` takes them; empty: one plain.
    std::string surfaces{};
    std::string time{};  // a time series: "time 3/8", "time 3/8 playing"; empty otherwise
};

// The two lines of the status bar: the isovalue (or the surfaces), its range, the frame, the clip
// planes and the last command;
// then the keys (keys_line).
std::vector<std::string> status_lines(const ControlStatus& s);
std::string keys_line();

// The window's size for `layout`: the mosaic with the status bar under it.
PixelSize control_window_size(const ControlLayout& layout);

// The mosaic alone (layout.mosaic's size): bezel grey, each tile's preview (by tile index; an
// image of 0x0 when none has come yet, shown black) scaled into its rect of the layout with
// resample_nearest, and a one-pixel grey frame round every tile. The browser page (wall --http)
// shows this.
Image compose_mosaic(const ControlLayout& layout, const std::vector<Image>& previews);

// The window's picture: bezel grey, each tile's preview (by tile index; an image of 0x0 when none
// has come yet, shown black) scaled into its rect of the layout, a one-pixel grey frame round
// every tile (so a seamless wall shows its seams too), and the status lines under the mosaic,
// each cut to the window's width.
Image compose_control(const ControlLayout& layout, const std::vector<Image>& previews,
                      const std::vector<std::string>& status);

}  // namespace isowall
