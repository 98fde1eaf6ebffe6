// The control window's input as script lines: each gesture becomes the command a script would
// hold, every line parses with parse_command, and bursts merge into one command.
#include <gtest/gtest.h>

#include "core/error.h"
#include "master/control_input.h"
#include "wall_spec/script.h"

namespace isowall {
namespace {

using Kind = WindowEvent::Kind;
using Lines = std::vector<std::string>;

WindowEvent press(int button, int x = 0, int y = 0) {
    return {Kind::press, x, y, button, ""};
}
WindowEvent release(int button, int x, int y) {
    return {Kind::release, x, y, button, ""};
}
WindowEvent motion(int x, int y) {
    return {Kind::motion, x, y, 0, ""};
}
WindowEvent key(const char* name) {
    return {Kind::key, 0, 0, 0, name};
}

// The phantom: values [0, 220], skin at 50, a 320x240 wall.
const ControlState kPhantom{50, 0, 220, 320, 240};

TEST(ControlInput, NoEventsNoCommands) {
    ControlInput in;
    EXPECT_EQ(in.commands({}, kPhantom), Lines{});
    // Motion without a button held, a release without a press, unknown keys and buttons.
    EXPECT_EQ(in.commands({motion(5, 5), release(1, 9, 9), key("F7"), press(2, 1, 1)}, kPhantom),
              Lines{});
    // A click without a drag orbits by nothing.
    EXPECT_EQ(in.commands({press(1, 10, 10), release(1, 10, 10)}, kPhantom), Lines{});
}

TEST(ControlInput, ALeftDragOrbitsHalfADegreePerPixelAsOneCommand) {
    ControlInput in;
    // xdotool's drag: press, a move, release. Right by 60 px turns the surface right.
    EXPECT_EQ(in.commands({press(1, 100, 100), motion(160, 100), release(1, 160, 100)}, kPhantom),
              Lines{"orbit -30 0"});
    // Many motions in one poll merge; down tilts the top towards the viewer.
    EXPECT_EQ(in.commands({press(1, 0, 0), motion(1, 2), motion(3, 4), motion(4, 10)}, kPhantom),
              Lines{"orbit -2 -5"});
    // The drag goes on into the next poll.
    EXPECT_EQ(in.commands({motion(2, 10), release(1, 2, 10)}, kPhantom), Lines{"orbit 1 0"});
    EXPECT_EQ(in.commands({motion(50, 50)}, kPhantom), Lines{});
}

TEST(ControlInput, ARightDragPansTheWallWithThePointer) {
    ControlInput in;
    EXPECT_EQ(in.commands({press(3, 0, 0), motion(32, -24), release(3, 32, -24)}, kPhantom),
              Lines{"pan -0.1 -0.1"});
}

TEST(ControlInput, WheelStepsZoomAndMerge) {
    ControlInput in;
    EXPECT_EQ(in.commands({press(4), release(4, 0, 0)}, kPhantom), Lines{"zoom 1.25"});
    EXPECT_EQ(in.commands({press(5)}, kPhantom), Lines{"zoom 0.8"});
    EXPECT_EQ(in.commands({press(4), press(4)}, kPhantom), Lines{"zoom 1.5625"});
    EXPECT_EQ(in.commands({press(4), press(5)}, kPhantom), Lines{});  // they cancel
}

TEST(ControlInput, IsovalueKeysStepByOnePercentOfTheRangeClamped) {
    ControlInput in;
    EXPECT_EQ(in.commands({key("Up")}, kPhantom), Lines{"iso 52.2"});
    EXPECT_EQ(in.commands({key("minus")}, kPhantom), Lines{"iso 47.8"});
    EXPECT_EQ(in.commands({key("plus"), key("KP_Add"), key("Up")}, kPhantom), Lines{"iso 56.6"});
    EXPECT_EQ(in.commands({key("Page_Up")}, kPhantom), Lines{"iso 72"});
    // Clamped to the range; nothing at all when already at the end.
    EXPECT_EQ(in.commands({key("Page_Down")}, {10, 0, 220, 1, 1}), Lines{"iso 0"});
    EXPECT_EQ(in.commands({key("Up")}, {220, 0, 220, 1, 1}), Lines{});
    // An empty range (a constant volume) has nowhere to go.
    EXPECT_EQ(in.commands({key("Up")}, {5, 5, 5, 1, 1}), Lines{});
}

TEST(ControlInput, LeftAndRightMoveTheHeadAndHomeBringsItBack) {
    ControlState state = kPhantom;
    // Without a step (the keys are off) nothing happens.
    ControlInput in;
    EXPECT_EQ(in.commands({key("Right"), key("Home")}, state), Lines{});
    state.head_step = kHeadStepMm;
    state.head = {0, -100, 0};
    const Lines lines = in.commands({key("Right"), key("Right"), key("Left"), key("Right")}, state);
    EXPECT_EQ(lines, Lines{"head 100 -100 0"});
    state.head = {100, -100, 0};
    EXPECT_EQ(in.commands({key("Home"), key("Left")}, state),
              (Lines{"head 0 0 0", "head -50 0 0"}));
    const ScriptCommand c = parse_command(lines[0], "control");
    ASSERT_TRUE(std::holds_alternative<HeadCmd>(c));
    EXPECT_EQ(std::get<HeadCmd>(c).offset, glm::dvec3(100, -100, 0));
}

TEST(ControlInput, CStepsThroughTheAxisClipsAndBracketsMoveThem) {
    ControlState state = kPhantom;
    ControlInput in;
    // Without the volume's size (the keys are off) nothing happens.
    EXPECT_EQ(in.commands({key("c"), key("bracketright")}, state), Lines{});
    state.dims = {200, 184, 168};
    EXPECT_EQ(in.commands({key("c"), key("c"), key("c"), key("c")}, state),
              (Lines{"clip x<99", "clip y<91", "clip z<83", "clip off"}));
    // A burst of moves is one command, 2% of the side (3.98 voxels of x) a key, in the volume.
    EXPECT_EQ(in.commands({key("c"), key("bracketright"), key("bracketright"), key("bracketleft")},
                          state),
              (Lines{"clip x<99", "clip x<102.98"}));
    state.clip = std::get<ClipCmd>(parse_command("clip x>190", "t")).clip;
    EXPECT_EQ(in.commands({key("bracketright"), key("bracketright"), key("bracketright")}, state),
              Lines{"clip x>199"});
    state.clip = std::get<ClipCmd>(parse_command("clip x>199", "t")).clip;
    EXPECT_EQ(in.commands({key("bracketright")}, state), Lines{});  // at the end already
    // Planes the keys did not make: c turns them off, brackets leave them.
    state.clip = std::get<ClipCmd>(parse_command("clip 1,1,0<50", "t")).clip;
    EXPECT_EQ(in.commands({key("bracketleft")}, state), Lines{});
    EXPECT_EQ(in.commands({key("c")}, state), Lines{"clip off"});
}

TEST(ControlInput, CommaAndPeriodStepThroughTimeAndPPlaysOrPauses) {
    ControlState state = kPhantom;
    ControlInput in;
    // Not a series: the keys do nothing.
    EXPECT_EQ(in.commands({key("period"), key("p")}, state), Lines{});
    state.steps = 8;
    state.step = 6;
    EXPECT_EQ(in.commands({key("period"), key("period"), key("comma")}, state),
              (Lines{"time 7", "time 6"}));  // no step past the last
    state.step = 0;
    EXPECT_EQ(in.commands({key("comma")}, state), Lines{});
    EXPECT_EQ(in.commands({key("p"), key("p")}, state), (Lines{"play loop", "pause"}));
    state.playing = true;
    EXPECT_EQ(in.commands({key("p")}, state), Lines{"pause"});
    for (const std::string& line : Lines{"time 7", "play loop", "pause"})
        EXPECT_NO_THROW(parse_command(line, "control")) << line;
}

TEST(ControlInput, KindsKeepTheirOrderAndQuitEndsThePoll) {
    ControlInput in(7);
    const Lines lines = in.commands({press(1, 0, 0), motion(10, 0), release(1, 10, 0), press(4),
                                     key("Up"), key("s"), key("Up"), key("Escape"), key("Up")},
                                    kPhantom);
    EXPECT_EQ(lines, (Lines{"orbit -5 0", "zoom 1.25", "iso 52.2", "snapshot control-007",
                            "iso 54.4", "quit"}));
    EXPECT_EQ(in.commands({key("s")}, kPhantom), Lines{"snapshot control-008"});
    EXPECT_EQ(in.commands({{Kind::close, 0, 0, 0, ""}, key("s")}, kPhantom), Lines{"quit"});
}

TEST(ControlInput, EveryLineParsesAsTheScriptCommandItNames) {
    ControlInput in;
    const Lines lines = in.commands({press(1, 0, 0), motion(7, 3), release(1, 7, 3), press(5),
                                     key("Down"), key("s"), key("Escape")},
                                    kPhantom);
    ASSERT_EQ(lines.size(), 5u);
    const ScriptCommand orbit = parse_command(lines[0], "control");
    EXPECT_DOUBLE_EQ(std::get<OrbitCmd>(orbit).yaw_deg, -3.5);
    EXPECT_DOUBLE_EQ(std::get<OrbitCmd>(orbit).pitch_deg, -1.5);
    EXPECT_FLOAT_EQ(std::get<ZoomCmd>(parse_command(lines[1], "control")).factor, 0.8f);
    EXPECT_DOUBLE_EQ(std::get<IsoCmd>(parse_command(lines[2], "control")).iso, 47.8);
    EXPECT_EQ(std::get<SnapshotCmd>(parse_command(lines[3], "control")).name, "control-001");
    EXPECT_TRUE(std::holds_alternative<QuitCmd>(parse_command(lines[4], "control")));
}

TEST(ControlInput, IsoLinesReadBackInsideTheRange) {
    EXPECT_EQ(iso_line(52.2, 0, 220), "iso 52.2");
    // Six digits would round past the top of the range: more are written.
    const double hi = 0.12345678;
    const std::string line = iso_line(hi, 0, hi);
    EXPECT_EQ(std::get<IsoCmd>(parse_command(line, "control")).iso, hi) << line;
    EXPECT_EQ(snapshot_name(1), "control-001");
    EXPECT_EQ(snapshot_name(1234), "control-1234");
}

}  // namespace
}  // namespace isowall
