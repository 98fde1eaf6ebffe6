#include "core/preview.h"

#include <algorithm>

#include "core/image_ops.h"

namespace isowall {

Preview make_preview(const Image& shown, std::uint64_t generation, int max_side) {
    Preview m;
    m.generation = generation;
    if (shown.width < 1 || shown.height < 1) return m;  // the default: one black pixel
    const int side = std::clamp(max_side, 1, kMaxPreviewSide);
    const Image small = shrink_box(shown, shrink_factor(shown.width, shown.height, side));
    m.width = small.width;
    m.height = small.height;
    m.rgb.resize(small.pixel_count() * 3);
    for (std::size_t i = 0; i < small.pixel_count(); ++i)
        for (int k = 0; k < 3; ++k) m.rgb[3 * i + k] = small.rgba[4 * i + k];
    return m;
}

Image preview_image(const Preview& preview) {
    Image img;
    img.width = preview.width;
    img.height = preview.height;
    img.rgba.assign(img.pixel_count() * 4, 255);
    for (std::size_t i = 0; i < img.pixel_count() && 3 * i + 2 < preview.rgb.size(); ++i)
        for (int k = 0; k < 3; ++k) img.rgba[4 * i + k] = preview.rgb[3 * i + k];
    return img;
}

}  // namespace isowall
