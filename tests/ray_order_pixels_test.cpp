// Ray-casting orders, what every kind shares: parsing its name, an empty or clipped rect, every
// rect pixel handed out exactly once (on small screens and a full 1600x1200 one), and coverage of
// the wrong size refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "progressive/ray_order.h"
#include "tests/ray_order_test_util.h"

namespace isowall {
namespace {

using namespace ray_order_testing;

constexpr RayOrderKind kAllKinds[] = {RayOrderKind::refining_grid, RayOrderKind::screen_readback,
                                      RayOrderKind::dynamic_grid, RayOrderKind::dynamic_gaps};

TEST(RayOrder, ParseAndToStringRoundTrip) {
    for (RayOrderKind k : kAllKinds) EXPECT_EQ(parse_ray_order(to_string(k)), k) << to_string(k);
    EXPECT_EQ(parse_ray_order("grid"), RayOrderKind::refining_grid);
    EXPECT_EQ(parse_ray_order("refining"), RayOrderKind::refining_grid);
    EXPECT_EQ(parse_ray_order("readback"), RayOrderKind::screen_readback);
    EXPECT_EQ(parse_ray_order("dynamic"), RayOrderKind::dynamic_grid);
    EXPECT_EQ(parse_ray_order(""), std::nullopt);
    EXPECT_EQ(parse_ray_order("Dynamic"), std::nullopt);
    EXPECT_EQ(parse_ray_order("dynamic_grid2"), std::nullopt);
}

TEST(RayOrder, EmptyRectGivesNoLevel) {
    const PixelRect empties[] = {{0, 0, 0, 0}, {5, 5, 0, 10}, {5, 5, 10, -3}, {300, 10, 20, 20}};
    for (RayOrderKind k : kAllKinds)
        for (const PixelRect& r : empties) {
            auto order = make_ray_order(k, 200, 100, r);
            std::vector<glm::ivec2> rays{{1, 1}};
            EXPECT_FALSE(order->wants_coverage()) << to_string(k) << " " << rect_str(r);
            EXPECT_FALSE(order->next_level(rays)) << to_string(k) << " " << rect_str(r);
            EXPECT_TRUE(rays.empty()) << to_string(k) << " " << rect_str(r);
            EXPECT_EQ(order->level(), -1) << to_string(k) << " " << rect_str(r);
            EXPECT_FALSE(order->wants_coverage()) << to_string(k) << " " << rect_str(r);
        }
}

TEST(RayOrder, EveryRectPixelExactlyOnce) {
    for (RayOrderKind k : kAllKinds)
        for (const ScreenCase& c : kCases) {
            DiskScene scene = scene_for(c.screen_w, c.screen_h, c.rect);
            auto order = make_ray_order(k, c.screen_w, c.screen_h, c.rect);
            const auto levels = run_order(*order, &scene);
            std::vector<int> count(std::size_t(c.screen_w) * c.screen_h, 0);
            for (const auto& level : levels)
                for (glm::ivec2 p : level) {
                    ASSERT_TRUE(p.x >= 0 && p.y >= 0 && p.x < c.screen_w && p.y < c.screen_h)
                        << to_string(k) << " " << rect_str(c.rect) << " pixel " << p.x << ","
                        << p.y;
                    ++count[std::size_t(p.y) * c.screen_w + p.x];
                }
            int wrong = 0;
            for (int y = 0; y < c.screen_h; ++y)
                for (int x = 0; x < c.screen_w; ++x) {
                    const bool inside = x >= c.rect.x && x < c.rect.x + c.rect.width &&
                                        y >= c.rect.y && y < c.rect.y + c.rect.height;
                    if (count[std::size_t(y) * c.screen_w + x] != (inside ? 1 : 0)) ++wrong;
                }
            EXPECT_EQ(wrong, 0) << to_string(k) << " " << rect_str(c.rect) << " on " << c.screen_w
                                << "x" << c.screen_h << ", " << levels.size() << " levels";
        }
}

TEST(RayOrder, RectIsClippedToTheScreen) {
    for (RayOrderKind k : kAllKinds) {
        auto order = make_ray_order(k, 50, 40, {-10, 30, 30, 30});
        DiskScene blank(50, 40, {});
        const auto levels = run_order(*order, &blank);
        std::size_t total = 0;
        for (const auto& level : levels)
            for (glm::ivec2 p : level) {
                EXPECT_TRUE(p.x >= 0 && p.x < 20 && p.y >= 30 && p.y < 40)
                    << to_string(k) << " pixel " << p.x << "," << p.y;
                ++total;
            }
        EXPECT_EQ(total, 20u * 10u) << to_string(k);
    }
}

TEST(RayOrder, CoverageOfTheWrongSizeThrows) {
    for (RayOrderKind k : kAllKinds) {
        auto order = make_ray_order(k, 20, 10, {0, 0, 20, 10});
        std::vector<glm::ivec2> rays;
        ASSERT_TRUE(order->next_level(rays));
        std::vector<std::uint8_t> covered(20 * 9, 0);
        EXPECT_THROW(order->set_coverage(covered), std::invalid_argument) << to_string(k);
    }
}

// A full 1600x1200 screen: every pixel exactly once. The per-level times are printed for the
// reader (about 10 ms for the 1.6 M-pixel fill level in a release build) but not asserted: the
// machines are shared and noisy, and speed is for benchmarks, not unit tests.
TEST(RayOrder, LargeScreenHandsOutEveryPixelOnce) {
    const int w = 1600, h = 1200;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> ux(0, w), uy(0, h), ur(20, 120);
    std::vector<Disk> disks;
    for (int i = 0; i < 12; ++i) disks.push_back({ux(rng), uy(rng), ur(rng)});
    disks.push_back({w * 0.5, h * 0.5, 150});
    for (RayOrderKind k : kAllKinds) {
        DiskScene scene(w, h, disks);
        auto order = make_ray_order(k, w, h, {0, 0, w, h});
        std::vector<glm::ivec2> rays;
        double worst_ms = 0, total_ms = 0;
        std::size_t total_rays = 0, outside = 0;
        std::vector<std::uint8_t> times(std::size_t(w) * h, 0);  // rays per pixel, saturating
        std::string figures;
        while (true) {
            std::vector<std::uint8_t> covered;
            if (order->wants_coverage()) covered = scene.coverage();  // outside the timing
            const auto t0 = std::chrono::steady_clock::now();
            if (!covered.empty()) order->set_coverage(covered);
            const bool more = order->next_level(rays);
            const double ms =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                    .count();
            if (!more) break;
            for (glm::ivec2 p : rays) {
                if (p.x < 0 || p.y < 0 || p.x >= w || p.y >= h) {
                    ++outside;
                    continue;
                }
                std::uint8_t& t = times[std::size_t(p.y) * w + p.x];
                t = std::uint8_t(std::min(t + 1, 255));
            }
            scene.cast(rays);
            worst_ms = std::max(worst_ms, ms);
            total_ms += ms;
            total_rays += rays.size();
            char buf[64];
            std::snprintf(buf, sizeof buf, " %zu:%.2f", rays.size(), ms);
            figures += buf;
        }
        EXPECT_EQ(total_rays, std::size_t(w) * h) << to_string(k);
        EXPECT_EQ(outside, 0u) << to_string(k);
        const auto once = std::count(times.begin(), times.end(), std::uint8_t{1});
        EXPECT_EQ(std::size_t(once), std::size_t(w) * h)
            << to_string(k) << ": " << std::count(times.begin(), times.end(), std::uint8_t{0})
            << " pixels never cast, "
            << std::count_if(times.begin(), times.end(), [](std::uint8_t t) { return t > 1; })
            << " cast more than once";
        std::printf(
            "[ ray order ] %-8s 1600x1200: worst level %.2f ms, all levels %.2f ms; "
            "rays:ms per level%s\n",
            std::string(to_string(k)).c_str(), worst_ms, total_ms, figures.c_str());
    }
}

}  // namespace
}  // namespace isowall
