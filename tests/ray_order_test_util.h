// Shared by the ray-order tests (ray_order_pixels_test.cpp, ray_order_levels_test.cpp): a
// synthetic screen of disks that are drawn whole when a ray hits them, a driver that runs an order
// to the end, and the screens and rects to run it on. Everything is inline and in a named
// namespace, so a test file that uses only some of it draws no unused-function warning.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "progressive/ray_order.h"

namespace isowall::ray_order_testing {

inline std::string rect_str(const PixelRect& r) {
    return "rect{" + std::to_string(r.x) + ", " + std::to_string(r.y) + ", " +
           std::to_string(r.width) + "x" + std::to_string(r.height) + "}";
}

struct Disk {
    double cx, cy, radius;
    bool contains(int x, int y) const {
        const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
        return dx * dx + dy * dy <= radius * radius;
    }
};

// A synthetic screen: each disk is a piece of surface that is drawn whole as soon as a ray hits
// one of its pixels, as propagation from a seed would draw it.
class DiskScene {
  public:
    DiskScene(int width, int height, std::vector<Disk> disks)
        : width_(width), height_(height), disks_(std::move(disks)), drawn_(disks_.size(), false) {}

    void cast(const std::vector<glm::ivec2>& rays) {
        for (glm::ivec2 p : rays)
            for (std::size_t d = 0; d < disks_.size(); ++d)
                if (disks_[d].contains(p.x, p.y)) drawn_[d] = true;
    }

    std::vector<std::uint8_t> coverage() const {
        std::vector<std::uint8_t> covered(std::size_t(width_) * std::size_t(height_), 0);
        for (std::size_t d = 0; d < disks_.size(); ++d) {
            if (!drawn_[d]) continue;
            const Disk& disk = disks_[d];
            const int x0 = std::max(0, int(disk.cx - disk.radius) - 1);
            const int x1 = std::min(width_, int(disk.cx + disk.radius) + 2);
            const int y0 = std::max(0, int(disk.cy - disk.radius) - 1);
            const int y1 = std::min(height_, int(disk.cy + disk.radius) + 2);
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x)
                    if (disks_[d].contains(x, y)) covered[std::size_t(y) * width_ + x] = 1;
        }
        return covered;
    }

  private:
    int width_, height_;
    std::vector<Disk> disks_;
    std::vector<bool> drawn_;
};

// A disk of a quarter of the rect's smaller side at its centre, and a smaller one near a corner.
inline DiskScene scene_for(int screen_w, int screen_h, const PixelRect& r) {
    const double small_side = std::min(r.width, r.height);
    return DiskScene(
        screen_w, screen_h,
        {{r.x + r.width * 0.5, r.y + r.height * 0.5, std::max(1.0, small_side / 4)},
         {r.x + r.width * 0.15, r.y + r.height * 0.8, std::max(1.0, small_side / 10)}});
}

// Runs an order to the end, feeding the scene's coverage whenever the order asks for it.
inline std::vector<std::vector<glm::ivec2>> run_order(RayOrder& order, DiskScene* scene) {
    std::vector<std::vector<glm::ivec2>> levels;
    std::vector<glm::ivec2> rays;
    while (true) {
        if (order.wants_coverage()) {
            EXPECT_NE(scene, nullptr) << "an order asked for coverage";
            if (scene) order.set_coverage(scene->coverage());
        }
        if (!order.next_level(rays)) break;
        EXPECT_FALSE(rays.empty()) << "level " << levels.size();
        EXPECT_EQ(order.level(), int(levels.size()));
        if (scene) scene->cast(rays);
        levels.push_back(rays);
    }
    EXPECT_FALSE(order.wants_coverage()) << "after the last level";
    return levels;
}

struct ScreenCase {
    int screen_w, screen_h;
    PixelRect rect;
};

// Screens and rects, from one pixel to a full 1600x1200 screen and a one-pixel-wide column.
inline const ScreenCase kCases[] = {
    {1, 1, {0, 0, 1, 1}},         {7, 5, {0, 0, 7, 5}},         {64, 48, {0, 0, 64, 48}},
    {200, 100, {37, 21, 90, 55}}, {200, 100, {199, 0, 1, 100}}, {1600, 1200, {0, 0, 1600, 1200}},
};

}  // namespace isowall::ray_order_testing
