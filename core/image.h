#pragma once
// A read-back frame: 8-bit RGBA colour and window-space depth, row 0 at the top.
#include <cstdint>
#include <vector>

namespace isowall {

// Largest image side a message may carry (wire/message_fields.h reads sides against it). A
// message over 2 GiB cannot travel (MPI counts are int); a tile is far smaller (a 4K display is
// 32 MiB of RGBA).
inline constexpr int kMaxImageSide = 32768;

struct Image {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgba;  // width*height*4, row-major from the top row
    std::vector<float> depth;        // width*height, window depth in [0,1]; 1 = nothing drawn

    void resize(int w, int h) {
        width = w;
        height = h;
        rgba.assign(static_cast<std::size_t>(w) * h * 4, 0);
        depth.assign(static_cast<std::size_t>(w) * h, 1.0f);
    }
    std::size_t pixel_count() const { return static_cast<std::size_t>(width) * height; }
    // A pixel is covered when something was drawn into it (depth < 1).
    bool covered(int x, int y) const {
        return depth[static_cast<std::size_t>(y) * width + x] < 1.0f;
    }
};

}  // namespace isowall
