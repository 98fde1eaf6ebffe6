#include "display/x_pixels.h"

namespace isowall {
namespace {

int lowest_bit(unsigned long mask) {
    int shift = 0;
    while (mask && !(mask & 1ul)) {
        mask >>= 1;
        ++shift;
    }
    return shift;
}

}  // namespace

PixelFormat PixelFormat::from_masks(unsigned long red, unsigned long green, unsigned long blue) {
    return {lowest_bit(red), lowest_bit(green), lowest_bit(blue)};
}

void pack_pixels(const Image& src, const PixelFormat& f, XImage& dst) {
    const bool fast = dst.bits_per_pixel == 32 && dst.byte_order == LSBFirst;
    for (int y = 0; y < dst.height; ++y) {
        const std::uint8_t* s = src.rgba.data() + (static_cast<std::size_t>(y) * src.width) * 4;
        auto* row = reinterpret_cast<std::uint32_t*>(dst.data + static_cast<std::size_t>(y) *
                                                                    dst.bytes_per_line);
        for (int x = 0; x < dst.width; ++x, s += 4) {
            const std::uint32_t v = (std::uint32_t{s[0]} << f.red_shift) |
                                    (std::uint32_t{s[1]} << f.green_shift) |
                                    (std::uint32_t{s[2]} << f.blue_shift);
            if (fast)
                row[x] = v;
            else
                XPutPixel(&dst, x, y, v);
        }
    }
}

void unpack_pixels(XImage& src, const PixelFormat& f, Image& dst) {
    dst.width = src.width;
    dst.height = src.height;
    dst.rgba.assign(static_cast<std::size_t>(src.width) * src.height * 4, 255);
    dst.depth.clear();
    std::uint8_t* d = dst.rgba.data();
    for (int y = 0; y < src.height; ++y)
        for (int x = 0; x < src.width; ++x, d += 4) {
            const unsigned long v = XGetPixel(&src, x, y);
            d[0] = static_cast<std::uint8_t>(v >> f.red_shift);
            d[1] = static_cast<std::uint8_t>(v >> f.green_shift);
            d[2] = static_cast<std::uint8_t>(v >> f.blue_shift);
        }
}

}  // namespace isowall
