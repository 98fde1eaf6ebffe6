#include "master/legend.h"

#include <algorithm>
#include <cstdio>
#include <string>

#include "master/control_text.h"

namespace isowall {

void draw_legend(Image& img, const ColourScale& scale, std::string_view label) {
    const int text_scale = img.width >= 640 ? 2 : 1;
    const int line = (kGlyphHeight + 2) * text_scale;
    const int margin = 4 * text_scale;
    const int bar_w = std::min(256 * text_scale / 2, img.width / 3);
    const int bar_h = 6 * text_scale;
    const int height = 2 * line + bar_h + 2 * margin;
    if (bar_w < 32 || img.height < height + margin) return;
    const int x0 = margin, y0 = img.height - height;
    // A dark plate, so the text reads over a bright surface as well as over the background.
    fill_rect(img, {0, y0 - margin, bar_w + 2 * margin, height + margin}, {16, 16, 16});
    const Rgb white{235, 235, 235};
    draw_text(img, x0, y0, label, text_scale, white);
    const int bar_y = y0 + line;
    for (int i = 0; i < bar_w; ++i) {
        const glm::u8vec3 c = scale.map.at((i + 0.5) / bar_w);
        fill_rect(img, {x0 + i, bar_y, 1, bar_h}, {c.x, c.y, c.z});
    }
    char lo[32], hi[32];
    std::snprintf(lo, sizeof(lo), "%g", scale.lo);
    std::snprintf(hi, sizeof(hi), "%g", scale.hi);
    const int ends_y = bar_y + bar_h + text_scale * 2;
    draw_text(img, x0, ends_y, lo, text_scale, white);
    draw_text(img, x0 + bar_w - text_width(hi, text_scale), ends_y, hi, text_scale, white);
}

}  // namespace isowall
