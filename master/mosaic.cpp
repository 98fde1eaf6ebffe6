#include "master/mosaic.h"

#include <algorithm>
#include <stdexcept>

namespace isowall {

Mosaic empty_mosaic(int width, int height) {
    Mosaic m;
    m.image.resize(width, height);
    for (std::size_t i = 0; i < m.image.pixel_count(); ++i) {
        for (int k = 0; k < 3; ++k) m.image.rgba[4 * i + k] = kBezelGrey;
        m.image.rgba[4 * i + 3] = 255;
    }
    m.count.assign(m.image.pixel_count(), 0);
    return m;
}

void paste(Mosaic& mosaic, const Image& tile, const PixelRect& where) {
    Image& out = mosaic.image;
    for_each_placed_pixel(out, tile, where, [&](std::size_t m, std::size_t t) {
        const int n = ++mosaic.count[m];
        for (int k = 0; k < 3; ++k) {
            const int before = n == 1 ? 0 : out.rgba[4 * m + k];
            out.rgba[4 * m + k] =
                static_cast<std::uint8_t>((before * (n - 1) + tile.rgba[4 * t + k]) / n);
        }
        out.rgba[4 * m + 3] = 255;
    });
}

}  // namespace isowall
