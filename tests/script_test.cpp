// Wall scripts: every command parses, every mistake names the file, line and command.
#include <gtest/gtest.h>

#include "core/error.h"
#include "wall_spec/script.h"

namespace isowall {
namespace {

TEST(Script, ParsesEveryCommand) {
    const auto lines = parse_script(
        "# a demo\n"
        "orbit 30 -10\n"
        "\n"
        "look-at 0 -500 100  255 255 117   # from the front\n"
        "zoom 1.5\n"
        "iso 105\n"
        "wait rays 10000\n"
        "wait time 0.5\n"
        "wait helped 3\n"
        "wait done\n"
        "snapshot bone\n"
        "quit",
        "demo.txt");
    ASSERT_EQ(lines.size(), 10u);
    EXPECT_EQ(lines[0].line, 2);
    EXPECT_FLOAT_EQ(std::get<OrbitCmd>(lines[0].command).pitch_deg, -10.0f);
    EXPECT_EQ(lines[1].line, 4);
    EXPECT_FLOAT_EQ(std::get<LookAtCmd>(lines[1].command).eye.y, -500.0f);
    EXPECT_FLOAT_EQ(std::get<ZoomCmd>(lines[2].command).factor, 1.5f);
    EXPECT_DOUBLE_EQ(std::get<IsoCmd>(lines[3].command).iso, 105.0);
    EXPECT_EQ(std::get<WaitCmd>(lines[4].command).until, WaitCmd::Until::rays);
    EXPECT_DOUBLE_EQ(std::get<WaitCmd>(lines[5].command).amount, 0.5);
    EXPECT_EQ(std::get<WaitCmd>(lines[6].command).until, WaitCmd::Until::helped);
    EXPECT_DOUBLE_EQ(std::get<WaitCmd>(lines[6].command).amount, 3.0);
    EXPECT_EQ(std::get<WaitCmd>(lines[7].command).until, WaitCmd::Until::done);
    EXPECT_EQ(std::get<SnapshotCmd>(lines[8].command).name, "bone");
    EXPECT_TRUE(std::holds_alternative<QuitCmd>(lines[9].command));
}

TEST(Script, ClipTakesPlanesABoxOrOff) {
    const auto lines = parse_script(
        "clip x<120 0,1,1>30\n"
        "clip box 10 20 30 100 110 120\n"
        "clip off\n",
        "c.txt");
    ASSERT_EQ(lines.size(), 3u);
    const ClipSet& planes = std::get<ClipCmd>(lines[0].command).clip;
    ASSERT_EQ(planes.count, 2u);
    EXPECT_TRUE(planes.keeps({100, 20, 20}));
    EXPECT_FALSE(planes.keeps({130, 20, 20}));
    EXPECT_FALSE(planes.keeps({100, 10, 10}));
    const ClipSet& box = std::get<ClipCmd>(lines[1].command).clip;
    EXPECT_EQ(box.count, 6u);
    EXPECT_TRUE(box.keeps({50, 50, 50}));
    EXPECT_FALSE(box.keeps({5, 50, 50}));
    EXPECT_TRUE(std::get<ClipCmd>(lines[2].command).clip.empty());
}

// `iso` with several surfaces: each VALUE[:COLOUR[:OPACITY]], kept in the one order every
// picture of them uses; one plain value stays a plain isovalue.
TEST(Script, IsoTakesSeveralSurfaces) {
    const auto lines = parse_script("iso 105:bone 40:skin:0.3\niso 60\niso 60::0.5\n", "i.txt");
    ASSERT_EQ(lines.size(), 3u);
    const IsoCmd& two = std::get<IsoCmd>(lines[0].command);
    ASSERT_EQ(two.surfaces.size(), 2u);
    EXPECT_EQ(two.iso, 40);
    EXPECT_EQ(two.surfaces[0].iso, 40);
    EXPECT_FLOAT_EQ(two.surfaces[0].opacity, 0.3f);
    EXPECT_EQ(two.surfaces[1].colour, glm::u8vec3(241, 214, 145));
    EXPECT_TRUE(std::get<IsoCmd>(lines[1].command).surfaces.empty());
    EXPECT_EQ(std::get<IsoCmd>(lines[2].command).surfaces.size(), 1u);
}

TEST(Script, EmptyScriptHasNoCommands) {
    EXPECT_TRUE(parse_script("", "e.txt").empty());
    EXPECT_TRUE(parse_script("# only a comment\n\n   \n", "e.txt").empty());
}

TEST(Script, MistakesNameTheFileLineAndCommand) {
    struct Case {
        const char* text;
        const char* mentions;
    };
    const Case cases[] = {
        {"orbit 30", "s.txt:1: orbit: expected \"orbit YAW PITCH\""},
        {"\nzoom -2", "s.txt:2: zoom: expected a number in [1e-06, 1e+06], got \"-2\""},
        {"iso abc", "s.txt:1: iso: expected a finite number, got \"abc\""},
        {"wait forever", "s.txt:1: wait: expected"},
        {"wait rays -5", "s.txt:1: wait: expected an integer in [0, "},
        {"wait helped 1.5", "s.txt:1: wait: expected an integer in [0, "},
        {"wait helped", "s.txt:1: wait: expected \"wait rays N\", \"wait helped N\""},
        {"snapshot a/b", "s.txt:1: snapshot: expected a plain name"},
        {"fly 1 2", "s.txt:1: command: unknown command \"fly\""},
        {"quit now", "s.txt:1: quit: expected \"quit\""},
        {"orbit 1 nan", "s.txt:1: orbit: expected a number"},
        // Found by fuzz/fuzz_script.cpp: numbers that are finite as doubles but not as floats,
        // and names that are not file names.
        {"look-at 0 0 0 1e300 0 0", "s.txt:1: look-at: expected a number in [-1e+06, 1e+06]"},
        {"pan 0 -1e39", "s.txt:1: pan: expected a number in [-1000, 1000]"},
        {"zoom 1e-50", "s.txt:1: zoom: expected a number in [1e-06, 1e+06], got \"1e-50\""},
        {"snapshot a\x01", "s.txt:1: snapshot: expected a plain name"},
        {"clip", "s.txt:1: clip: expected \"clip PLANE...\""},
        {"clip x<<3", "s.txt:1: clip: expected x<N, y>N, z<N or A,B,C<D"},
        {"clip 0,0,0<1", "s.txt:1: clip: the plane's direction A,B,C is zero"},
        {"clip x<1e300", "s.txt:1: clip: expected a number in [-1e6, 1e6]"},
        {"clip x<1 x<2 x<3 x<4 x<5 x<6 x<7 x<8 x<9", "s.txt:1: clip: expected \"clip PLANE...\""},
        {"clip box 0 0 0 10 10", "s.txt:1: clip: expected \"clip PLANE...\""},
        {"clip box 0 0 0 10 0 10", "s.txt:1: clip: expected X0 < X1, Y0 < Y1 and Z0 < Z1"},
        {"clip box 0 0 0 10 10 2e6", "s.txt:1: clip: expected a number in [-1e+06, 1e+06]"},
        {"iso", "s.txt:1: iso: expected \"iso V\", got 0 argument(s)"},
        {"iso 40:mauve", "s.txt:1: iso: unknown colour 'mauve'"},
        {"iso 40:skin:2", "s.txt:1: iso: expected an opacity in [0, 1]"},
        {"iso 40 40:red", "s.txt:1: iso: isovalue 40 given twice"},
        {"iso 40 abc", "s.txt:1: iso: expected an isovalue before ':', got 'abc'"},
    };
    for (const Case& c : cases) {
        try {
            parse_script(c.text, "s.txt");
            ADD_FAILURE() << "no error for: " << c.text;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(c.mentions), std::string::npos)
                << "got: " << e.what() << "\nwanted: " << c.mentions;
        }
    }
}

}  // namespace
}  // namespace isowall
