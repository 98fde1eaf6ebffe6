#pragma once
// Text for the control window's status bar, drawn into an image with a built-in 3x5 pixel font:
// the window needs no font server and no X text call, and the text shows in a capture.
#include <array>
#include <cstdint>
#include <string_view>

#include "core/camera.h"  // PixelRect
#include "core/image.h"

namespace isowall {

using Rgb = std::array<std::uint8_t, 3>;

// Each glyph is 3x5 cells with one blank column after it; `scale` pixels per cell.
inline constexpr int kGlyphWidth = 3, kGlyphHeight = 5;
int text_width(std::string_view text, int scale);

// Draws `text` with its top-left at (x, y) of img, each cell scale x scale pixels; what falls
// outside img is clipped. Letters have one case (upper and lower look alike); a character
// without a glyph shows as a filled box, so an unexpected one is noticed.
void draw_text(Image& img, int x, int y, std::string_view text, int scale, Rgb colour);

// Fills the rect (clipped to img) with colour, alpha 255.
void fill_rect(Image& img, const PixelRect& r, Rgb colour);

}  // namespace isowall
