// The control window (isowall wall --control) under mpirun on a private Xvfb: a drag, a wheel step
// and an isovalue key sent with xdotool, and a pan from the wall's page (--http, a WebSocket client
// here) in the same steering loop, change the final mosaic to the one the equivalent script
// gives (the acceptance rule of the wall tests: mask IoU >= 0.999, >= 99.9% of pixels within
// 1/255), and a display that cannot open ends every rank with one line naming it.
//
// Sync is on what the master prints, never on a fixed sleep: "control: window on" once the window
// serves, "control: frame N done" when every tile has finished a frame (after the last command's
// line, it is that command's frame), "snapshot:" when a snapshot is written.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/image_ops.h"
#include "core/preview.h"
#include "core/util.h"
#include "display/x_window.h"
#include "files/image_io.h"
#include "master/control_input.h"
#include "master/control_view.h"
#include "tests/image_compare.h"
#include "tests/run_util.h"
#include "tests/test_util.h"
#include "tests/ws_test_client.h"
#include "tests/xvfb_util.h"
#include "wall_spec/control_layout.h"

namespace isowall {
namespace {

using test::mpirun;
using test::run;
using test::slurp;

const test::CompareOptions kFromFiles{.coverage = test::Coverage::colour};
constexpr int kGuardS = 180;  // the wall's own limit (timeout) in every run here

// The gestures and the script lines they must become (master/control_input.h): a drag of kDragPx
// to the right at kOrbitDegPerPx, one wheel step up, one Up key (1% of the phantom's [0, 220]
// from its skin isovalue 50). Horizontal only, so the orbit adds up exactly however the motion
// is cut into polls.
constexpr int kDragPx = 60;
static_assert(kOrbitDegPerPx == 0.5 && kZoomStep == 1.25 && kIsoStep == 0.01,
              "the script below spells out these constants");
const char* const kScript = "orbit -30 0\nzoom 1.25\niso 52.2\npan 0.1 0\nwait done\nquit\n";

bool have(const char* program) {
    return std::system(("command -v " + std::string(program) + " >/dev/null 2>&1").c_str()) == 0;
}

// Polls `log` until `ready(text)` holds, for at most `limit_s`; returns whether it did.
bool wait_for(const std::filesystem::path& log,
              const std::function<bool(const std::string&)>& ready, double limit_s) {
    Stopwatch waited;
    while (waited.seconds() < limit_s) {
        if (ready(slurp(log))) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return ready(slurp(log));
}

bool contains(const std::string& text, const std::string& what) {
    return text.find(what) != std::string::npos;
}

// A "control: frame N done" line after the last occurrence of `after`.
bool done_after(const std::string& text, const std::string& after) {
    const auto at = text.rfind(after);
    return at != std::string::npos && text.find(" done in ", at) != std::string::npos;
}

// The wall with --control, running in the background; on destruction (a failed assertion
// included) it is ended if it still runs.
class ControlRun {
  public:
    ControlRun(const std::filesystem::path& dir, const std::string& display) : dir_(dir) {
        const std::string cmd = "(timeout " + std::to_string(kGuardS) + " " + mpirun(5) +
                                "wall --wall '" + (dir / "2x2.toml").string() + "' --out '" +
                                (dir / "control.png").string() + "' --control --control-display " +
                                display + " --http 0 > '" + log().string() + "' 2>&1; echo $? > '" +
                                (dir / "rc").string() + "') & echo $! > '" +
                                (dir / "pid").string() + "'";
        std::system(
            ("export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; " + cmd).c_str());
    }
    ~ControlRun() {
        if (std::filesystem::exists(dir_ / "rc") || !std::filesystem::exists(dir_ / "pid")) return;
        // The subshell's child is `timeout`, which passes SIGTERM on to mpirun and its ranks.
        std::system(("pkill -TERM -P $(cat '" + (dir_ / "pid").string() + "')").c_str());
    }
    ControlRun(const ControlRun&) = delete;
    ControlRun& operator=(const ControlRun&) = delete;

    std::filesystem::path log() const { return dir_ / "control.log"; }
    // The exit code once the run has ended within limit_s, else -1.
    int exit_code(double limit_s) const {
        if (!wait_for(
                dir_ / "rc", [](const std::string& t) { return !t.empty(); }, limit_s))
            return -1;
        return std::atoi(slurp(dir_ / "rc").c_str());
    }

  private:
    std::filesystem::path dir_;
};

class ControlWindowTest : public testing::Test {
  protected:
    void SetUp() override {
        if (!x_.ok()) GTEST_SKIP() << "no Xvfb: " << x_.why_not();
        if (!have("xdotool")) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh)";
        if (!have("mpirun")) GTEST_SKIP() << "mpirun is not installed";
    }
    // xdotool on the private display; what it prints goes to `out` (its chatter to stderr).
    int xdotool(const std::string& args, const std::string& out = "xdotool.log") const {
        return std::system(("DISPLAY=" + x_.display() + " timeout 60 xdotool " + args + " > '" +
                            (dir_ / out).string() + "' 2>> '" + (dir_ / "xdotool.err").string() +
                            "'")
                               .c_str());
    }
    test::Xvfb x_{{"1280x1024"}};
    std::filesystem::path dir_ = test::scratch_dir("control_window");
};

// The master's line with the page's port (wall --http 0).
const std::string kPageAt = "http: page at http://127.0.0.1:";
int page_port(const std::string& log) {
    return std::atoi(log.c_str() + log.find(kPageAt) + kPageAt.size());
}

// "WHO: LINE" of every line the page was told ran, until `last` is among them (at most 10 s:
// states keep coming, so the page never falls silent).
std::string heard_lines(test::WsTestClient& page, const std::string& last) {
    std::string heard;
    for (Stopwatch reading; reading.seconds() < 10 && !contains(heard, last);)
        if (auto m = page.receive(0.5); m && m->bytes.starts_with("{")) {
            const auto j = nlohmann::json::parse(m->bytes);
            if (j["type"] == "ran")
                heard += j["who"].get<std::string>() + ": " + j["line"].get<std::string>() + "\n";
        }
    return heard;
}

// The mosaic part of the control window (status bar aside), as it should show `mosaic`: each
// tile's previews composed by the window's own layout (tiles at full size on this small wall).
Image expected_control_mosaic(const WallSpec& spec, const Image& mosaic) {
    const ControlLayout layout = control_layout(spec);
    std::vector<Image> previews;
    for (int t = 0; t < tile_count(spec); ++t)
        previews.push_back(preview_image(
            make_preview(crop(mosaic, tile_rect(spec, t)), 1, preview_max_side(spec))));
    const Image all = compose_control(layout, previews, {});
    return crop(all, {0, 0, layout.mosaic.width, layout.mosaic.height});
}

// Captures the control window until its mosaic matches `expected` (previews arrive paced), at
// most `limit_s`; returns the last comparison.
test::ImageComparison wait_for_previews(const std::string& display, const std::string& window,
                                        const Image& expected, double limit_s) {
    test::ImageComparison m;
    Stopwatch waited;
    do {
        const Image shown = capture_window(display, std::stoull(window));
        m = test::compare_images(crop(shown, {0, 0, expected.width, expected.height}), expected,
                                 kFromFiles);
        if (m.equal_share >= 0.999) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    } while (waited.seconds() < limit_s);
    return m;
}

// The wall's final mosaic (control.png) equals the one kScript gives (script.png).
void expect_the_scripts_mosaic(const std::filesystem::path& dir, double control_s) {
    std::ofstream(dir / "same.txt") << kScript;
    Stopwatch took;
    ASSERT_EQ(
        run(mpirun(5) + "wall --wall '" + (dir / "2x2.toml").string() + "' --out '" +
                (dir / "script.png").string() + "' --script '" + (dir / "same.txt").string() + "'",
            dir / "script.log", kGuardS),
        0)
        << slurp(dir / "script.log");
    const double script_s = took.seconds();

    const Image control = read_image(dir / "control.png");
    const Image script = read_image(dir / "script.png");
    const test::ImageComparison same = test::compare_images(control, script, kFromFiles);
    std::printf("control window vs script: %s\ncontrol run %.1f s, script run %.1f s\n",
                testing::PrintToString(same).c_str(), control_s, script_s);
    EXPECT_GT(same.covered_both, 1000u) << same;  // an empty pair would agree trivially
    EXPECT_GE(same.mask_iou, 0.999) << same;
    EXPECT_GE(same.equal_share, 0.999) << same;
    if (same.mask_iou < 0.999 || same.equal_share < 0.999)
        test::write_diff_images(dir, "control_vs_script", control, script, kFromFiles);
}

TEST_F(ControlWindowTest, DragWheelAndIsoKeyGiveTheMosaicOfTheEquivalentScript) {
    std::ofstream(dir_ / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [160, 120]\n";
    Stopwatch took;
    ControlRun wall(dir_, x_.display());
    ASSERT_TRUE(wait_for(
        wall.log(), [](const std::string& t) { return contains(t, "control: window on"); }, 120))
        << slurp(wall.log());
    // The page beside the window (wall --http): it hears every line, the window's too.
    ASSERT_TRUE(wait_for(
        wall.log(), [&](const std::string& t) { return contains(t, kPageAt); }, 60))
        << slurp(wall.log());
    test::WsTestClient page(page_port(slurp(wall.log())));
    page.send_text(R"({"hello": ""})");
    ASSERT_EQ(xdotool("search --sync --name '^isowall control$'", "window"), 0);
    const std::string w = std::to_string(std::atoll(slurp(dir_ / "window").c_str()));
    ASSERT_NE(w, "0") << slurp(dir_ / "window");
    // The first view, kept as a snapshot (the s key) to show that the gestures changed it.
    ASSERT_TRUE(wait_for(
        wall.log(), [](const std::string& t) { return contains(t, "control: frame 1 done"); }, 60))
        << slurp(wall.log());
    ASSERT_EQ(xdotool("key --window " + w + " s"), 0);
    ASSERT_TRUE(wait_for(
        wall.log(), [](const std::string& t) { return contains(t, "snapshot: "); }, 60))
        << slurp(wall.log());
    // The window shows the tiles' previews of that frame: the wall as it stands.
    const test::ImageComparison live = wait_for_previews(
        x_.display(), w,
        expected_control_mosaic(load_wall(dir_ / "2x2.toml"), read_image(dir_ / "control-001.png")),
        20);
    std::printf("control window vs the snapshot's previews: %s\n",
                testing::PrintToString(live).c_str());
    EXPECT_GT(live.covered_both, 1000u) << live;
    EXPECT_GE(live.equal_share, 0.999) << live;
    // The drag, the wheel step, the isovalue key.
    ASSERT_EQ(xdotool("mousemove --window " + w + " 100 100 mousedown 1 mousemove --window " + w +
                      " " + std::to_string(100 + kDragPx) + " 100 mouseup 1"),
              0);
    ASSERT_EQ(xdotool("click --window " + w + " 4"), 0);
    ASSERT_EQ(xdotool("key --window " + w + " Up"), 0);
    ASSERT_TRUE(wait_for(
        wall.log(), [](const std::string& t) { return done_after(t, "control: iso "); }, 60))
        << slurp(wall.log());
    page.send_text(R"({"run": "pan 0.1 0"})");
    ASSERT_TRUE(wait_for(
        wall.log(), [](const std::string& t) { return done_after(t, "page 1: pan "); }, 60))
        << slurp(wall.log());
    const std::string heard = heard_lines(page, "page 1: pan");
    EXPECT_TRUE(contains(heard, "control: orbit -30 0\n")) << heard;
    EXPECT_TRUE(contains(heard, "page 1: pan 0.1 0\n")) << heard;
    ASSERT_EQ(xdotool("key --window " + w + " Escape"), 0);
    const int rc = wall.exit_code(60);
    const double control_s = took.seconds();
    const std::string log = slurp(wall.log());
    ASSERT_EQ(rc, 0) << log;
    // Each gesture became one command, the line a script would hold.
    for (const char* line :
         {"control: orbit -30 0\n", "control: zoom 1.25\n", "control: iso 52.2\n",
          "page 1: pan 0.1 0\n", "control: snapshot control-001\n", "control: quit\n"})
        EXPECT_EQ(test::count_of(log, line), 1u) << line << " in:\n" << log;

    expect_the_scripts_mosaic(dir_, control_s);
    // The gestures changed the view: the first one is far from the last.
    const test::ImageComparison first = test::compare_images(
        read_image(dir_ / "control-001.png"), read_image(dir_ / "control.png"), kFromFiles);
    std::printf("first view vs after the gestures: %s\n", testing::PrintToString(first).c_str());
    EXPECT_LT(first.equal_share, 0.9) << first;
}

TEST(ControlWindow, ADisplayThatCannotOpenEndsEveryRankNamingIt) {
    if (!have("mpirun")) GTEST_SKIP() << "mpirun is not installed";
    const auto dir = test::scratch_dir("control_no_display");
    std::ofstream(dir / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [160, 120]\n";
    // A display number no test server takes (Xvfb -displayfd picks from 0 up).
    const int rc = run(mpirun(5) + "wall --wall '" + (dir / "2x2.toml").string() + "' --out '" +
                           (dir / "m.png").string() + "' --control --control-display :4095",
                       dir / "wall.log", 60);
    const std::string log = slurp(dir / "wall.log");
    EXPECT_NE(rc, 0) << log;
    EXPECT_NE(rc, 124) << "still running after 60 s: " << log;
    EXPECT_EQ(test::count_of(log, "isowall: error:"), 1u) << log;
    EXPECT_TRUE(contains(log, "isowall: error: rank 0 (master): ")) << log;
    EXPECT_TRUE(contains(log, "\":4095\"")) << log;
    EXPECT_FALSE(std::filesystem::exists(dir / "m.png"));
}

TEST(ControlWindow, TheConsoleAndTheWindowAreNotBothTaken) {
    if (!have("mpirun")) GTEST_SKIP() << "mpirun is not installed";
    const auto dir = test::scratch_dir("control_and_console");
    std::ofstream(dir / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [160, 120]\n";
    const int rc = run(mpirun(5) + "wall --wall '" + (dir / "2x2.toml").string() + "' --out '" +
                           (dir / "m.png").string() + "' --control --script - < /dev/null",
                       dir / "wall.log", 60);
    const std::string log = slurp(dir / "wall.log");
    EXPECT_EQ(rc, 1) << log;
    EXPECT_EQ(test::count_of(log, "isowall: error: --control: --script: "), 1u) << log;
}

}  // namespace
}  // namespace isowall
