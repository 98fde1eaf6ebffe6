// display/: windows on a private Xvfb. What is presented is what a capture reads back, through
// MIT-SHM and without; a fullscreen window covers its screen; events arrive; a missing display
// is one DisplayError naming it.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <string>

#include "display/x_window.h"
#include "tests/xvfb_util.h"

namespace isowall {
namespace {

Image gradient(int w, int h) {
    Image img;
    img.resize(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            std::uint8_t* p = &img.rgba[(static_cast<std::size_t>(y) * w + x) * 4];
            p[0] = static_cast<std::uint8_t>(x * 255 / (w - 1));
            p[1] = static_cast<std::uint8_t>(y * 255 / (h - 1));
            p[2] = static_cast<std::uint8_t>((x + y) & 255);
            p[3] = 255;
        }
    return img;
}

// Pixels of `a` (at offset x0, y0 of `window`) that differ from the capture in any channel.
int differing(const Image& a, const Image& window, int x0, int y0) {
    int n = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const auto va = a.rgba[(static_cast<std::size_t>(y) * a.width + x) * 4 + c];
                const auto vw =
                    window.rgba[(static_cast<std::size_t>(y + y0) * window.width + x + x0) * 4 + c];
                if (va != vw) {
                    ++n;
                    break;
                }
            }
    return n;
}

class Display : public ::testing::Test {
  protected:
    void SetUp() override {
        if (!x_.ok()) GTEST_SKIP() << "no Xvfb: " << x_.why_not();
    }
    test::Xvfb x_{{"320x200", "160x120"}};
};

TEST_F(Display, FullscreenWindowsCoverTheirScreenAndShowExactlyWhatWasPresented) {
    for (int screen : {0, 1}) {
        XWindow w({x_.screen(screen), "tile " + std::to_string(screen), true});
        EXPECT_EQ(w.width(), screen == 0 ? 320 : 160);
        EXPECT_EQ(w.height(), screen == 0 ? 200 : 120);
        const Image img = gradient(w.width(), w.height());
        w.present(img);
        EXPECT_TRUE(w.shared_memory()) << "Xvfb on this host shares memory";
        const Image got = capture_window(x_.screen(screen), w.id());
        ASSERT_EQ(got.width, w.width());
        EXPECT_EQ(differing(img, got, 0, 0), 0);
        EXPECT_EQ(find_window(x_.screen(screen), "tile " + std::to_string(screen)), w.id());
    }
}

TEST_F(Display, APresentAtAnOffsetIsClippedToTheWindowWithoutSharedMemoryToo) {
    XWindow w({x_.display(), "clip", false, 100, 80, false, false});
    const Image img = gradient(90, 70);
    w.present(img, 20, 30);  // 80 x 50 of it fit
    EXPECT_FALSE(w.shared_memory());
    const Image got = capture_window(x_.display(), w.id());
    Image part;
    part.resize(80, 50);
    for (int y = 0; y < 50; ++y)
        for (int x = 0; x < 80; ++x)
            for (int c = 0; c < 4; ++c)
                part.rgba[(static_cast<std::size_t>(y) * 80 + x) * 4 + c] =
                    img.rgba[(static_cast<std::size_t>(y) * 90 + x) * 4 + c];
    EXPECT_EQ(differing(part, got, 20, 30), 0);
    EXPECT_EQ(got.rgba[0], 0) << "outside the present the window stays black";
}

TEST_F(Display, AMissingDisplayIsOneErrorNamingIt) {
    try {
        XWindow w({":9997", "none", true});
        FAIL() << "opened a display that does not exist";
    } catch (const DisplayError& e) {
        EXPECT_NE(std::string(e.what()).find("\":9997\""), std::string::npos) << e.what();
    }
    EXPECT_EQ(resolve_display(":3.1"), ":3.1");
}

TEST_F(Display, MouseAndKeyEventsArriveInWindowPixels) {
    if (system("command -v xdotool > /dev/null") != 0) GTEST_SKIP() << "no xdotool";
    XWindow w({x_.display(), "events", false, 200, 150, true});
    const std::string cmd = "DISPLAY=" + x_.display() + " xdotool mousemove --window " +
                            std::to_string(w.id()) + " 30 40 mousedown 1 mousemove --window " +
                            std::to_string(w.id()) + " 70 40 mouseup 1 click 5 key Escape";
    ASSERT_EQ(system(cmd.c_str()), 0) << cmd;
    std::vector<WindowEvent> all;
    for (int i = 0; i < 100 && (all.empty() || all.back().key != "Escape"); ++i) {
        for (auto& e : w.poll()) all.push_back(e);
        usleep(20000);
    }
    ASSERT_FALSE(all.empty());
    EXPECT_EQ(all.back().key, "Escape");
    int presses = 0, wheel_down = 0, last_x = -1;
    for (const auto& e : all) {
        if (e.kind == WindowEvent::Kind::press && e.button == 1) {
            ++presses;
            EXPECT_EQ(e.x, 30);
            EXPECT_EQ(e.y, 40);
        }
        if (e.kind == WindowEvent::Kind::press && e.button == 5) ++wheel_down;
        if (e.kind == WindowEvent::Kind::release && e.button == 1) last_x = e.x;
    }
    EXPECT_EQ(presses, 1);
    EXPECT_EQ(wheel_down, 1);
    EXPECT_EQ(last_x, 70);
}

TEST(PresentPacer, ShowsAtMostOncePerIntervalAndKeepsTheLastChangePending) {
    PresentPacer p(0.1);
    EXPECT_TRUE(p.changed(0.0));
    EXPECT_FALSE(p.changed(0.05));
    EXPECT_TRUE(p.pending());
    EXPECT_FALSE(p.due(0.09));
    EXPECT_TRUE(p.due(0.11));
    EXPECT_FALSE(p.pending());
    EXPECT_FALSE(p.due(0.5)) << "nothing pending";
    EXPECT_TRUE(p.changed(0.5));
}

}  // namespace
}  // namespace isowall
