#pragma once
// The legend of a surface coloured by a second field: its name, the colour bar and the values at
// its ends, drawn into the bottom-left corner of an image that is written out (render's --out,
// the wall's mosaics), with the control window's built-in font. The picture the engine measures
// never carries it.
#include <string_view>

#include "core/colour_map.h"
#include "core/image.h"

namespace isowall {

// Draws the legend of `scale`, titled `label` (lower case; letters, digits and . , : - + = / % _
// show), into `img`; an image too small for it (under about 120 x 50 pixels) is left as it is.
void draw_legend(Image& img, const ColourScale& scale, std::string_view label);

}  // namespace isowall
