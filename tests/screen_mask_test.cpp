// The screen mask as a pure function (hand-built boxes against screen_box, pixel by pixel) and the
// ray orders under a mask: masked pixels are never handed out, and a rect masked out entirely
// gives no level.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/ray.h"
#include "progressive/ray_order.h"
#include "progressive/screen_mask.h"
#include "tests/ray_order_test_util.h"

namespace isowall {
namespace {

using ray_order_testing::rect_str;

// Object space = view space; the view box spans [-1, 1] in x and y.
Frustum ortho() {
    Frustum f;
    f.projection = Projection::orthographic;
    return f;
}

Frustum perspective() {
    Frustum f;  // 90 degrees: [-1, 1] at the near plane 1
    f.near_z = 1;
    return f;
}

Box3 box(glm::vec3 lo, glm::vec3 hi) {
    Box3 b;
    b.merge(lo);
    b.merge(hi);
    return b;
}

bool inside(const PixelRect& r, int x, int y) {
    return x >= r.x && y >= r.y && x < r.x + r.width && y < r.y + r.height;
}

bool set_at(const ScreenMask& m, int x, int y) {
    if (!inside(m.rect, x, y)) return false;
    return m.cast[std::size_t(y - m.rect.y) * std::size_t(m.rect.width) +
                  std::size_t(x - m.rect.x)] != 0;
}

// Every pixel of the screen: in the mask exactly when some box's screen_box, clipped to the
// region, holds it; the rect is the tight bounding box and count the number set.
void expect_union_of_screen_boxes(const std::vector<Box3>& boxes, const Frustum& f, int w, int h,
                                  PixelRect region) {
    const glm::mat4 view(1.0f);
    const ScreenMask m = screen_mask(boxes, view, f, w, h, region);
    std::size_t count = 0;
    int x0 = w, y0 = h, x1 = -1, y1 = -1;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool want = false;
            for (const Box3& b : boxes)
                want = want || (inside(screen_box(b, view, f, w, h), x, y) && inside(region, x, y));
            ASSERT_EQ(set_at(m, x, y), want) << "pixel " << x << "," << y << " " << m;
            if (!want) continue;
            ++count;
            x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
        }
    EXPECT_EQ(m.count, count) << m;
    if (count == 0) {
        EXPECT_EQ(m.rect.width * m.rect.height, 0) << m;
        return;
    }
    EXPECT_EQ(m.rect.x, x0) << m;
    EXPECT_EQ(m.rect.y, y0) << m;
    EXPECT_EQ(m.rect.width, x1 - x0 + 1) << m;
    EXPECT_EQ(m.rect.height, y1 - y0 + 1) << m;
}

TEST(ScreenMask, NoBoxesOrAnEmptyRegionMaskEverythingOut) {
    const glm::mat4 view(1.0f);
    const std::vector<Box3> none;
    EXPECT_EQ(screen_mask(none, view, ortho(), 20, 20, {0, 0, 20, 20}).count, 0u);
    const std::vector<Box3> one{box({-0.5f, -0.5f, -2}, {0.5f, 0.5f, -1})};
    EXPECT_EQ(screen_mask(one, view, ortho(), 20, 20, {0, 0, 0, 0}).count, 0u);
    EXPECT_EQ(screen_mask(one, view, ortho(), 20, 20, {25, 0, 10, 10}).count, 0u);
    EXPECT_EQ(screen_mask(std::vector<Box3>{Box3{}}, view, ortho(), 20, 20, {0, 0, 20, 20}).count,
              0u)
        << "an empty (inverted) box covers nothing";
}

TEST(ScreenMask, OneBoxIsItsScreenBoxWithOnePixelOfMargin) {
    // x in [-0.5, -0.4] -> pixels 5..6 of 20, y in [0.4, 0.5] -> rows 5..6; one pixel of margin.
    const std::vector<Box3> b{box({-0.5f, 0.4f, -2}, {-0.4f, 0.5f, -1})};
    const ScreenMask m = screen_mask(b, glm::mat4(1.0f), ortho(), 20, 20, {0, 0, 20, 20});
    EXPECT_EQ(rect_str(m.rect), rect_str({4, 4, 3, 3})) << m;
    EXPECT_EQ(m.count, 9u);
}

TEST(ScreenMask, TwoBoxesLeaveTheGapBetweenThemOut) {
    const std::vector<Box3> b{box({-0.9f, -0.9f, -2}, {-0.8f, -0.8f, -1}),
                              box({0.8f, 0.8f, -2}, {0.9f, 0.9f, -1})};
    const ScreenMask m = screen_mask(b, glm::mat4(1.0f), ortho(), 40, 40, {0, 0, 40, 40});
    EXPECT_FALSE(set_at(m, 20, 20)) << m;
    EXPECT_LT(m.count, std::size_t(m.rect.width) * std::size_t(m.rect.height) / 4) << m;
    expect_union_of_screen_boxes(b, ortho(), 40, 40, {0, 0, 40, 40});
}

TEST(ScreenMask, ABoxAcrossTheEyePlaneCoversTheWholeRegion) {
    const std::vector<Box3> b{box({-0.1f, -0.1f, -1}, {0.1f, 0.1f, 1})};  // holds the eye
    const PixelRect region{3, 2, 10, 7};
    const ScreenMask m = screen_mask(b, glm::mat4(1.0f), perspective(), 16, 12, region);
    EXPECT_EQ(rect_str(m.rect), rect_str(region)) << m;
    EXPECT_EQ(m.count, 70u);
}

TEST(ScreenMask, RandomBoxesAreTheUnionOfTheirScreenBoxesInTheRegion) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> xy(-1.5f, 1.5f), size(0.0f, 0.4f), depth(-8.0f, -1.5f);
    const PixelRect regions[] = {{0, 0, 33, 27}, {5, 4, 17, 11}, {-3, 20, 50, 30}};
    for (const Frustum& f : {ortho(), perspective()})
        for (const PixelRect& region : regions)
            for (int n : {1, 3, 12}) {
                std::vector<Box3> boxes;
                for (int i = 0; i < n; ++i) {
                    const glm::vec3 lo(xy(rng), xy(rng), depth(rng));
                    boxes.push_back(box(lo, lo + glm::vec3(size(rng), size(rng), size(rng))));
                }
                SCOPED_TRACE(rect_str(region) + " boxes " + std::to_string(n));
                expect_union_of_screen_boxes(boxes, f, 33, 27, region);
            }
}

// Runs `order` to the end: every pixel it hands out, in order.
std::vector<glm::ivec2> drain(RayOrder& order) {
    std::vector<glm::ivec2> all, level;
    while (order.next_level(level)) all.insert(all.end(), level.begin(), level.end());
    return all;
}

TEST(RayOrderMask, MaskedPixelsAreNeverHandedOutAndTheRestExactlyOnce) {
    const int w = 37, h = 23;
    std::vector<std::uint8_t> mask(std::size_t(w) * h, 0);
    std::mt19937 rng(3);
    for (auto& m : mask) m = rng() % 3 == 0 ? 1 : 0;
    const PixelRect rect{2, 1, 30, 20};
    for (RayOrderKind k :
         {RayOrderKind::refining_grid, RayOrderKind::screen_readback, RayOrderKind::dynamic_grid}) {
        auto order = make_ray_order(k, w, h, rect, mask);
        std::vector<int> seen(std::size_t(w) * h, 0);
        for (const glm::ivec2 p : drain(*order)) ++seen[std::size_t(p.y) * w + std::size_t(p.x)];
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const std::size_t i = std::size_t(y) * w + std::size_t(x);
                const int want = inside(rect, x, y) && mask[i] != 0 ? 1 : 0;
                ASSERT_EQ(seen[i], want) << to_string(k) << " pixel " << x << "," << y;
            }
    }
}

TEST(RayOrderMask, ARectMaskedOutEntirelyGivesNoLevel) {
    const std::vector<std::uint8_t> none(16 * 9, 0);
    for (RayOrderKind k :
         {RayOrderKind::refining_grid, RayOrderKind::screen_readback, RayOrderKind::dynamic_grid}) {
        auto order = make_ray_order(k, 16, 9, {0, 0, 16, 9}, none);
        std::vector<glm::ivec2> level;
        EXPECT_FALSE(order->next_level(level)) << to_string(k);
        EXPECT_TRUE(level.empty());
        EXPECT_FALSE(order->wants_coverage());
    }
}

TEST(RayOrderMask, AMaskOfTheWrongSizeIsRefused) {
    const std::vector<std::uint8_t> small(10, 1);
    EXPECT_THROW(make_ray_order(RayOrderKind::dynamic_grid, 16, 9, {0, 0, 16, 9}, small),
                 std::invalid_argument);
}

}  // namespace
}  // namespace isowall
