#include "master/control_view.h"

#include <cstdio>

#include "core/image_ops.h"

namespace isowall {
namespace {

// Outlines rect r (clipped to img) with a one-pixel line.
void frame_rect(Image& img, const PixelRect& r, Rgb colour) {
    if (r.width <= 0 || r.height <= 0) return;
    fill_rect(img, {r.x, r.y, r.width, 1}, colour);
    fill_rect(img, {r.x, r.y + r.height - 1, r.width, 1}, colour);
    fill_rect(img, {r.x, r.y, 1, r.height}, colour);
    fill_rect(img, {r.x + r.width - 1, r.y, 1, r.height}, colour);
}

}  // namespace

std::vector<std::string> status_lines(const ControlStatus& s) {
    char first[200];
    std::snprintf(first, sizeof(first), "iso %g  [%g, %g]   frame %llu %s", s.iso, s.value_min,
                  s.value_max, static_cast<unsigned long long>(s.frame),
                  s.done ? "done" : "running");
    std::string line = first;
    if (!s.surfaces.empty()) line = "iso " + s.surfaces + line.substr(line.find("  ["));
    if (!s.time.empty()) line += "   " + s.time;
    if (!s.clip.empty()) line += "   clip " + s.clip;
    if (!s.last.empty()) line += "   last: " + s.last;
    return {line, keys_line()};
}

std::string keys_line() {
    return "drag orbit  right-drag pan  wheel zoom  up/down iso  pgup/pgdn iso x10  left/right "
           "head  c clip  [ ] move it  , . time  p play  s snapshot  esc quit";
}

PixelSize control_window_size(const ControlLayout& layout) {
    return {layout.mosaic.width, layout.mosaic.height + kControlStatusHeight};
}

namespace {

// The mosaic of the control window into the top of `img` (at least the mosaic's size).
void draw_mosaic(Image& img, const ControlLayout& layout, const std::vector<Image>& previews) {
    fill_rect(img, {0, 0, layout.mosaic.width, layout.mosaic.height}, kControlBezel);
    for (std::size_t t = 0; t < layout.tiles.size(); ++t) {
        const PixelRect& r = layout.tiles[t];
        if (r.width <= 0 || r.height <= 0) continue;
        if (t < previews.size() && previews[t].width > 0 && previews[t].height > 0)
            place(img, resample_nearest(previews[t], r.width, r.height), r);
        else
            fill_rect(img, r, {0, 0, 0});
    }
    for (const PixelRect& r : layout.tiles) frame_rect(img, r, kControlBezel);
}

Image blank(PixelSize size) {
    Image img;
    img.width = size.width;
    img.height = size.height;
    img.rgba.assign(img.pixel_count() * 4, 255);
    return img;
}

}  // namespace

Image compose_mosaic(const ControlLayout& layout, const std::vector<Image>& previews) {
    Image img = blank(layout.mosaic);
    draw_mosaic(img, layout, previews);
    return img;
}

Image compose_control(const ControlLayout& layout, const std::vector<Image>& previews,
                      const std::vector<std::string>& status) {
    const PixelSize size = control_window_size(layout);
    Image img = blank(size);
    draw_mosaic(img, layout, previews);
    const PixelRect bar{0, layout.mosaic.height, size.width, kControlStatusHeight};
    fill_rect(img, bar, kControlStatusBackground);
    const int line_height = (kGlyphHeight + 2) * kControlTextScale;
    const int fit = (size.width - 4 + kControlTextScale) / ((kGlyphWidth + 1) * kControlTextScale);
    for (std::size_t i = 0; i < status.size() && i < 2; ++i) {
        const std::string text = status[i].substr(0, static_cast<std::size_t>(std::max(fit, 0)));
        draw_text(img, 4, bar.y + 3 + static_cast<int>(i) * line_height, text, kControlTextScale,
                  kControlStatusText);
    }
    return img;
}

}  // namespace isowall
