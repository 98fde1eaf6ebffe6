#include "core/image_ops.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <utility>

namespace isowall {

void composite_by_depth(Image& dst, const Image& src, const PixelRect& where) {
    if (dst.depth.size() != dst.pixel_count() || src.depth.size() != src.pixel_count())
        throw std::invalid_argument("composite_by_depth: both images need depth");
    for_each_placed_pixel(dst, src, where, [&](std::size_t d, std::size_t s) {
        if (src.depth[s] >= dst.depth[d]) return;
        dst.depth[d] = src.depth[s];
        for (int k = 0; k < 4; ++k) dst.rgba[4 * d + k] = src.rgba[4 * s + k];
    });
}

Image composite_layers(const std::vector<const Image*>& layers, const std::vector<float>& opacity) {
    if (layers.empty() || layers.size() != opacity.size())
        throw std::invalid_argument("composite_layers: one opacity a layer, and a layer at least");
    const Image& first = *layers[0];
    for (const Image* l : layers)
        if (l->width != first.width || l->height != first.height ||
            l->depth.size() != l->pixel_count() || l->rgba.size() != 4 * l->pixel_count())
            throw std::invalid_argument("composite_layers: layers of one size, with depth");
    Image out;
    out.resize(first.width, first.height);
    std::vector<std::size_t> order(layers.size());
    for (std::size_t p = 0; p < out.pixel_count(); ++p) {
        std::size_t n = 0;
        for (std::size_t k = 0; k < layers.size(); ++k)
            if (layers[k]->depth[p] < 1.0f) order[n++] = k;
        if (n == 0) {  // the background, as the first layer's frame has it
            for (int ch = 0; ch < 4; ++ch) out.rgba[4 * p + ch] = first.rgba[4 * p + ch];
            continue;
        }
        // Back to front: farther first; at equal depth the later layer first, so the earlier ends
        // in front. n is at most a handful: an insertion sort.
        auto behind = [&](std::size_t a, std::size_t b) {
            const float da = layers[a]->depth[p], db = layers[b]->depth[p];
            return da != db ? da > db : a > b;
        };
        for (std::size_t i = 1; i < n; ++i)
            for (std::size_t j = i; j > 0 && behind(order[j], order[j - 1]); --j)
                std::swap(order[j], order[j - 1]);
        float c[3] = {0, 0, 0};
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t k = order[i];
            const float a = std::clamp(opacity[k], 0.0f, 1.0f);
            for (int ch = 0; ch < 3; ++ch)
                c[ch] = a * float(layers[k]->rgba[4 * p + ch]) + (1 - a) * c[ch];
        }
        for (int ch = 0; ch < 3; ++ch)
            out.rgba[4 * p + ch] = static_cast<std::uint8_t>(std::lround(std::min(c[ch], 255.0f)));
        out.rgba[4 * p + 3] = 255;
        out.depth[p] = layers[order[n - 1]]->depth[p];
    }
    return out;
}

void place(Image& dst, const Image& src, const PixelRect& where) {
    const bool depth =
        dst.depth.size() == dst.pixel_count() && src.depth.size() == src.pixel_count();
    for_each_placed_pixel(dst, src, where, [&](std::size_t d, std::size_t s) {
        if (depth) dst.depth[d] = src.depth[s];
        for (int k = 0; k < 4; ++k) dst.rgba[4 * d + k] = src.rgba[4 * s + k];
    });
}

int shrink_factor(int width, int height, int max_side) {
    const int side = std::max({width, height, 1});
    const int limit = std::max(max_side, 1);
    return (side + limit - 1) / limit;
}

Image shrink_box(const Image& src, int factor) {
    const int f = std::max(factor, 1);
    Image out;
    out.width = (src.width + f - 1) / f;
    out.height = (src.height + f - 1) / f;
    out.rgba.assign(out.pixel_count() * 4, 255);
    for (int oy = 0; oy < out.height; ++oy) {
        const int y0 = oy * f, y1 = std::min(y0 + f, src.height);
        for (int ox = 0; ox < out.width; ++ox) {
            const int x0 = ox * f, x1 = std::min(x0 + f, src.width);
            std::uint32_t sum[3] = {0, 0, 0};
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) {
                    const std::size_t s = 4 * (static_cast<std::size_t>(y) * src.width + x);
                    for (int k = 0; k < 3; ++k) sum[k] += src.rgba[s + k];
                }
            const auto n = static_cast<std::uint32_t>((y1 - y0) * (x1 - x0));
            const std::size_t o = 4 * (static_cast<std::size_t>(oy) * out.width + ox);
            for (int k = 0; k < 3; ++k)
                out.rgba[o + k] = static_cast<std::uint8_t>((sum[k] + n / 2) / n);
        }
    }
    return out;
}

Image resample_nearest(const Image& src, int width, int height) {
    Image out;
    out.width = std::max(width, 0);
    out.height = std::max(height, 0);
    out.rgba.assign(out.pixel_count() * 4, 0);
    for (std::size_t i = 0; i < out.pixel_count(); ++i) out.rgba[4 * i + 3] = 255;
    if (src.width < 1 || src.height < 1) return out;
    for (int y = 0; y < out.height; ++y) {
        // The source pixel under the centre of this one, in 64 bits (sides up to 32768 each).
        const auto sy = static_cast<int>((2 * std::int64_t{y} + 1) * src.height / (2 * out.height));
        for (int x = 0; x < out.width; ++x) {
            const auto sx =
                static_cast<int>((2 * std::int64_t{x} + 1) * src.width / (2 * out.width));
            const std::size_t s = 4 * (static_cast<std::size_t>(sy) * src.width + sx);
            const std::size_t o = 4 * (static_cast<std::size_t>(y) * out.width + x);
            for (int k = 0; k < 3; ++k) out.rgba[o + k] = src.rgba[s + k];
        }
    }
    return out;
}

PixelRect covered_box(const Image& img) {
    if (img.depth.size() != img.pixel_count()) return {};
    int x0 = img.width, y0 = img.height, x1 = -1, y1 = -1;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            if (img.depth[std::size_t(y) * std::size_t(img.width) + std::size_t(x)] < 1.0f) {
                x0 = std::min(x0, x);
                x1 = std::max(x1, x);
                y0 = std::min(y0, y);
                y1 = std::max(y1, y);
            }
    if (x1 < 0) return {};
    return {x0, y0, x1 - x0 + 1, y1 - y0 + 1};
}

Image crop(const Image& img, const PixelRect& r) {
    Image out;
    out.width = r.width;
    out.height = r.height;
    out.rgba.resize(std::size_t(r.width) * std::size_t(r.height) * 4);
    const bool depth = img.depth.size() == img.pixel_count();
    if (depth) out.depth.resize(std::size_t(r.width) * std::size_t(r.height));
    for (int y = 0; y < r.height; ++y) {
        const std::size_t from = std::size_t(r.y + y) * std::size_t(img.width) + std::size_t(r.x);
        const std::size_t to = std::size_t(y) * std::size_t(r.width);
        std::copy_n(img.rgba.begin() + std::ptrdiff_t(from * 4), std::size_t(r.width) * 4,
                    out.rgba.begin() + std::ptrdiff_t(to * 4));
        if (depth)
            std::copy_n(img.depth.begin() + std::ptrdiff_t(from), r.width,
                        out.depth.begin() + std::ptrdiff_t(to));
    }
    return out;
}

}  // namespace isowall
