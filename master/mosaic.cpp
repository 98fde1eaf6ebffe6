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

namespace {

// The pixel of `img` that pixel (x, y) of a width x height image falls on.
const std::uint8_t* stretched(const Image& img, int x, int y, int width, int height) {
    const int sx = std::min(img.width - 1, int(std::int64_t(x) * img.width / width));
    const int sy = std::min(img.height - 1, int(std::int64_t(y) * img.height / height));
    return &img.rgba[4 * (std::size_t(sy) * std::size_t(img.width) + std::size_t(sx))];
}

}  // namespace

Image anaglyph(const Image& left, const Image& right, int width, int height) {
    if (left.width <= 0 || left.height <= 0 || right.width <= 0 || right.height <= 0)
        throw std::invalid_argument("anaglyph of an empty image");
    Image out;
    out.resize(width, height);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::uint8_t* l = stretched(left, x, y, width, height);
            const std::uint8_t* r = stretched(right, x, y, width, height);
            std::uint8_t* o = &out.rgba[4 * (std::size_t(y) * std::size_t(width) + std::size_t(x))];
            o[0] = l[0];
            o[1] = r[1];
            o[2] = r[2];
            o[3] = 255;
        }
    return out;
}

std::vector<std::pair<std::filesystem::path, Image>> mosaic_files(const std::filesystem::path& path,
                                                                  std::vector<Mosaic> mosaics,
                                                                  int width, int height) {
    std::vector<std::pair<std::filesystem::path, Image>> files;
    if (mosaics.size() == 1) {
        files.emplace_back(path, std::move(mosaics[0].image));
        return files;
    }
    if (mosaics.size() != 2) throw std::invalid_argument("a wall has one mosaic or two eyes'");
    const auto eye_path = [&](const char* eye) {
        return path.parent_path() / (path.stem().string() + "-" + eye + path.extension().string());
    };
    files.emplace_back(path, anaglyph(mosaics[0].image, mosaics[1].image, width, height));
    files.emplace_back(eye_path("left"), std::move(mosaics[0].image));
    files.emplace_back(eye_path("right"), std::move(mosaics[1].image));
    return files;
}

}  // namespace isowall
