// `isowall wall --windows` on a private Xvfb with one screen per tile (the wall file's display
// keys): while the wall runs, the test captures every tile window as fast as it can (XGetImage)
// and keeps each distinct picture. The last picture of each window must equal the tile image the
// rank wrote at quit (>= 99.9% of pixels within 1/255), and an earlier one must be a frame part
// built (covering pixels, but fewer than the final): the window shows progress, not only the end.
// A display that does not exist is one line naming the rank, host and display.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "display/x_window.h"
#include "files/image_io.h"
#include "tests/image_compare.h"
#include "tests/run_util.h"
#include "tests/test_util.h"
#include "tests/xvfb_util.h"
#include "tile/tile_window.h"

namespace isowall {
namespace {

using test::mpirun;
using test::run;

const test::CompareOptions kColour{.coverage = test::Coverage::colour};

std::string wall_file(const std::string& display, int w, int h) {
    std::string s =
        "tiles = [2, 2]\ntile_size_px = [" + std::to_string(w) + ", " + std::to_string(h) + "]\n";
    for (int t = 0; t < 4; ++t)
        s += "[[tile]]\ncolumn = " + std::to_string(t % 2) + "\nrow = " + std::to_string(t / 2) +
             "\ndisplay = \"" + display + "." + std::to_string(t) + "\"\n";
    return s;
}

std::size_t covered(const Image& img) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < img.pixel_count(); ++i)
        n += (img.rgba[4 * i] | img.rgba[4 * i + 1] | img.rgba[4 * i + 2]) != 0;
    return n;
}

// Where window `id` sits on its screen, as xwininfo says ("Absolute upper-left X"); -1 unknown.
int window_x(const std::string& display, std::uint64_t id) {
    const std::string cmd =
        "xwininfo -display '" + display + "' -id " + std::to_string(id) + " 2>/dev/null";
    std::FILE* p = popen(cmd.c_str(), "r");
    if (!p) return -1;
    char line[256];
    int x = -1;
    while (std::fgets(line, sizeof(line), p)) std::sscanf(line, " Absolute upper-left X: %d", &x);
    pclose(p);
    return x;
}

// Every distinct picture tile `t`'s window (of `eye`, with stereo) showed while `running` holds;
// `x`, when given, where the window sits on its screen.
std::vector<Image> watch(const test::Xvfb& x, int t, const std::atomic<bool>& running,
                         Eye eye = Eye::centre, int* at = nullptr) {
    std::vector<Image> seen;
    std::uint64_t id = 0;
    while (running) {
        try {
            if (!id) {
                id = find_window(x.screen(t), tile_window_title(t, eye));
                if (id && at) *at = window_x(x.screen(t), id);
            }
            if (!id) continue;
            Image img = capture_window(x.screen(t), id);
            if (seen.empty() || img.rgba != seen.back().rgba) seen.push_back(std::move(img));
        } catch (const DisplayError&) {
            id = 0;  // the window has closed (the run is ending)
        }
    }
    return seen;
}

TEST(TileWindows, ShowTheFrameAsItBuildsAndThenExactlyTheTileImage) {
    test::Xvfb x({"320x240", "320x240", "320x240", "320x240"});
    if (!x.ok()) GTEST_SKIP() << "no Xvfb: " << x.why_not();
    const auto dir = test::scratch_dir("tile_windows");
    std::ofstream(dir / "wall.toml") << wall_file(x.display(), 320, 240);
    // The frame is held on screen for 1.5 s after it is done (`wait time` is a pause, which does
    // not end with the frame), so the last captures are of it. It once ended with the frame, and
    // a tile's last change, shown at its next refresh, then sometimes came after the quit.
    std::ofstream(dir / "show.txt") << "wait done\nwait time 1.5\nquit\n";
    std::atomic<bool> running{true};
    int rc = -1;
    // --max-count 4: many small groups, so the frame takes long enough to be seen building.
    std::thread wall([&] {
        rc =
            run(mpirun(5) + "wall --windows --max-count 4 --wall '" + (dir / "wall.toml").string() +
                    "' --script '" + (dir / "show.txt").string() + "' --tiles-out '" +
                    dir.string() + "' --out '" + (dir / "m.png").string() + "'",
                dir / "log.txt");
        running = false;
    });
    // One watcher per window, so each is captured as often as the X server allows.
    std::vector<std::vector<Image>> seen(4);
    {
        std::vector<std::thread> watchers;
        for (int t = 0; t < 4; ++t)
            watchers.emplace_back([&, t] { seen[t] = watch(x, t, running); });
        wall.join();
        for (auto& w : watchers) w.join();
    }
    ASSERT_EQ(rc, 0) << test::slurp(dir / "log.txt");
    for (int t = 0; t < 4; ++t) {
        SCOPED_TRACE("tile " + std::to_string(t));
        ASSERT_FALSE(seen[t].empty()) << "the window never showed";
        const Image final_tile = read_image(dir / ("tile_" + std::to_string(t) + ".png"));
        // The last capture may be of the black window once the rank has ended: take the last
        // one that shows anything.
        std::size_t last = seen[t].size();
        while (last > 0 && covered(seen[t][last - 1]) == 0) --last;
        ASSERT_GT(last, 0u) << "the window showed nothing";
        const Image& shown = seen[t][last - 1];
        const auto m = test::compare_images(shown, final_tile, kColour);
        std::cout << "tile " << t << ": " << seen[t].size() << " distinct pictures; last vs tile "
                  << "image: " << m << "\n";
        EXPECT_GE(m.equal_share, 0.999) << m;
        EXPECT_GE(m.mask_iou, 0.999) << m;
        bool partial = false;
        for (std::size_t i = 0; i + 1 < last && !partial; ++i) {
            const std::size_t c = covered(seen[t][i]);
            partial = c > 0 && c < covered(final_tile) * 99 / 100;
        }
        EXPECT_TRUE(partial) << "no capture showed the frame part built";
    }
}

// The last picture a window showed that shows anything (the window may be black once its rank
// has ended).
const Image* last_lit(const std::vector<Image>& seen) {
    for (auto it = seen.rbegin(); it != seen.rend(); ++it)
        if (covered(*it) > 0) return &*it;
    return nullptr;
}

// A side-by-side stereo wall: each tile's screen shows its left eye's frame on its left half and
// its right eye's on its right half, each the eye's tile image.
TEST(TileWindows, StereoEyesShowOnTheirHalvesOfTheTilesScreen) {
    test::Xvfb x({"320x240", "320x240", "320x240", "320x240"});
    if (!x.ok()) GTEST_SKIP() << "no Xvfb: " << x.why_not();
    const auto dir = test::scratch_dir("tile_windows_stereo");
    std::ofstream(dir / "wall.toml")
        << wall_file(x.display(), 320, 240)
        << "[stereo]\nmode = \"side-by-side\"\neye_separation = 0.05\n";
    std::ofstream(dir / "show.txt") << "wait done\nwait time 1.5\nquit\n";
    std::atomic<bool> running{true};
    int rc = -1;
    std::thread wall([&] {
        rc = run(mpirun(9) + "wall --windows --wall '" + (dir / "wall.toml").string() +
                     "' --script '" + (dir / "show.txt").string() + "' --tiles-out '" +
                     dir.string() + "' --out '" + (dir / "m.png").string() + "'",
                 dir / "log.txt");
        running = false;
    });
    std::vector<std::vector<Image>> seen(8);
    std::vector<int> at(8, -1);
    {
        std::vector<std::thread> watchers;
        for (int k = 0; k < 8; ++k)
            watchers.emplace_back([&, k] {
                seen[k] = watch(x, k / 2, running, k % 2 ? Eye::right : Eye::left, &at[k]);
            });
        wall.join();
        for (auto& w : watchers) w.join();
    }
    ASSERT_EQ(rc, 0) << test::slurp(dir / "log.txt");
    for (int k = 0; k < 8; ++k) {
        const std::string eye = k % 2 ? "right" : "left";
        SCOPED_TRACE("tile " + std::to_string(k / 2) + ", " + eye + " eye");
        const Image* shown = last_lit(seen[k]);
        ASSERT_NE(shown, nullptr) << "the window showed nothing";
        EXPECT_EQ(shown->width, 160);
        EXPECT_EQ(shown->height, 240);
        EXPECT_EQ(at[k], k % 2 ? 160 : 0) << "the eye's window is not on its half";
        const Image tile = read_image(dir / ("tile_" + std::to_string(k / 2) + "-" + eye + ".png"));
        const auto m = test::compare_images(*shown, tile, kColour);
        EXPECT_GE(m.equal_share, 0.999) << m;
    }
}

TEST(TileWindows, ADisplayThatDoesNotExistIsOneLineNamingRankHostAndDisplay) {
    test::Xvfb x({"64x48"});
    if (!x.ok()) GTEST_SKIP() << "no Xvfb: " << x.why_not();
    const auto dir = test::scratch_dir("tile_windows_missing");
    // Tile 0's display works; tile 1's does not exist.
    std::ofstream(dir / "wall.toml")
        << "tiles = [2, 1]\ntile_size_px = [64, 48]\ndisplay = \"" << x.display()
        << "\"\n[[tile]]\ncolumn = 1\nrow = 0\ndisplay = \":9998\"\n";
    const int rc = run(mpirun(3) + "wall --windows --wall '" + (dir / "wall.toml").string() +
                           "' --out '" + (dir / "m.png").string() + "' --timeout 10",
                       dir / "log.txt", 60);
    const std::string log = test::slurp(dir / "log.txt");
    EXPECT_NE(rc, 0) << log;
    EXPECT_NE(log.find("isowall: error: rank 2 (tile 1): on host "), std::string::npos) << log;
    EXPECT_NE(log.find("cannot open X display \":9998\""), std::string::npos) << log;
    std::size_t lines = 0;
    for (std::size_t p = log.find("isowall: error:"); p != std::string::npos;
         p = log.find("isowall: error:", p + 1))
        ++lines;
    EXPECT_EQ(lines, 1u) << log;
    EXPECT_FALSE(std::filesystem::exists(dir / "m.png")) << "no partial output";
}

}  // namespace
}  // namespace isowall
