// Every number a wall file carries, against every class of hostile value: one line naming the
// file and the dotted field; no NaN, infinity or int overflow reaches the tile geometry.
#include <gtest/gtest.h>

#include <fstream>

#include "core/error.h"
#include "tests/test_util.h"
#include "wall_spec/wall.h"

namespace isowall {
namespace {

struct WallSlot {
    std::string text;   // a wall file with {} where the value goes
    std::string field;  // the field its error names
};

const std::string kGrid = "tiles = [2, 2]\ntile_size_px = [100, 80]\n";
const std::string kPhys = kGrid + "[physical]\ntile_size_mm = [400, 300]\n";

const std::vector<WallSlot> kWallSlots = {
    {"tiles = [{}, 2]\ntile_size_px = [100, 80]\n", "tiles"},
    {"tiles = [2, 2]\ntile_size_px = [100, {}]\n", "tile_size_px"},
    {kGrid + "bezel_px = {}\n", "bezel_px"},
    {kGrid + "bezel_px = { left = {} }\n", "bezel_px.left"},
    {kGrid + "[[tile]]\ncolumn = 0\nrow = 0\noffset_px = [{}, 0]\n", "tile[0].offset_px"},
    {kGrid + "[[tile]]\ncolumn = {}\nrow = 0\n", "tile[0].column"},
    {kGrid + "[physical]\ntile_size_mm = [{}, 300]\n", "physical.tile_size_mm"},
    {kPhys + "bezel_mm = {}\n", "physical.bezel_mm"},
    {kPhys + "bezel_mm = { top = {} }\n", "physical.bezel_mm.top"},
    {kPhys + "viewer_mm = [0, {}, 1000]\n", "physical.viewer_mm"},
    {kPhys + "viewer_mm = [0, 0, {}]\n", "physical.viewer_mm"},
};

std::string wall_fill(const std::string& slot, const std::string& value) {
    std::string text = slot;
    return text.replace(text.find("{}"), 2, value);
}

TEST(WallNumbers, NoFieldTakesNonFiniteOrHugeValues) {
    int tried = 0;
    for (const WallSlot& s : kWallSlots)
        for (const char* bad : {"nan", "+nan", "-nan", "inf", "+inf", "-inf", "1e300", "-1e300",
                                "9223372036854775807", "-9223372036854775808", "2147483648", "1e8",
                                "\"5\"", "true"}) {
            const std::string text = wall_fill(s.text, bad);
            try {
                const WallSpec w = parse_wall(text, "bad.toml");
                ADD_FAILURE() << s.field << " = " << bad << ": accepted " << w;
            } catch (const InputError& e) {
                const std::string msg = e.what();
                EXPECT_EQ(msg.rfind("bad.toml: " + s.field + ": expected", 0), 0u)
                    << bad << ": " << msg;
                EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
            }
            ++tried;
        }
    EXPECT_EQ(tried, 11 * 14);
}

TEST(WallNumbers, TheVirtualScreenFitsInInt) {
    struct Case {
        std::string text, field;
    };
    const std::vector<Case> cases = {
        {"tiles = [1000, 1]\ntile_size_px = [32768, 80]\n", "tiles"},
        {"tiles = [2, 1000]\ntile_size_px = [100, 32768]\n", "tiles"},
        {"tiles = [2, 2]\ntile_size_px = [32769, 80]\n", "tile_size_px"},
        {"tiles = [1000, 1]\ntile_size_px = [100, 80]\nbezel_px = 1000000\n", "bezel_px"},
        {"tiles = [3, 1]\ntile_size_px = [100, 80]\n[physical]\ntile_size_mm = [1e-300, 300]\n"
         "bezel_mm = 1\n",
         "physical.tile_size_mm"},
        {"tiles = [3, 1]\ntile_size_px = [100, 80]\n[physical]\ntile_size_mm = [1e-3, 300]\n"
         "bezel_mm = 1000\n",
         "physical.bezel_mm"},
    };
    for (const Case& c : cases) {
        try {
            const WallSpec w = parse_wall(c.text, "big.toml");
            ADD_FAILURE() << "accepted " << w << " with screen " << virtual_screen_size(w).width;
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()).rfind("big.toml: " + c.field + ": ", 0), 0u)
                << e.what();
        }
    }
    const WallSpec ok = parse_wall("tiles = [4, 1]\ntile_size_px = [32768, 80]\n", "ok.toml");
    EXPECT_EQ(virtual_screen_size(ok).width, 131072);
}

TEST(WallNumbers, ErrorsQuoteABoundedPartOfTheFile) {
    const std::string huge(5 << 20, 'q');
    const std::vector<std::string> texts = {
        kGrid + "rank_order = \"" + huge + "\"\n", kGrid + huge + " = 1\n",
        "tiles = [" + std::string(200000, '1').insert(1, ", ") + "]\n",
        kGrid + "rank_order = \"\x1b[2J\"\n"};
    for (const std::string& text : texts) {
        try {
            parse_wall(text, "w.toml");
            ADD_FAILURE() << "accepted " << text.substr(0, 60);
        } catch (const InputError& e) {
            EXPECT_LT(std::string(e.what()).size(), 600u) << std::string(e.what()).substr(0, 200);
            EXPECT_EQ(std::string(e.what()).find('\x1b'), std::string::npos);
        }
    }
}

TEST(WallNumbers, AWallFileMustBeARegularFile) {
    const auto dir = test::scratch_dir("wall_files");
    std::filesystem::create_directory(dir / "folder.toml");
    std::ofstream(dir / "huge.toml") << std::string(kMaxWallFileBytes + 1, '#');
    struct Case {
        std::filesystem::path path;
        const char* mentions;
    };
    for (const Case& c :
         {Case{dir / "folder.toml", "is a folder"}, Case{"/dev/zero", "not a regular file"},
          Case{dir / "huge.toml", "expected at most"}}) {
        try {
            load_wall(c.path);
            ADD_FAILURE() << "accepted " << c.path;
        } catch (const InputError& e) {
            const std::string msg = e.what();
            EXPECT_EQ(msg.rfind(c.path.string() + ": file: ", 0), 0u) << msg;
            EXPECT_NE(msg.find(c.mentions), std::string::npos) << msg;
        }
    }
}

}  // namespace
}  // namespace isowall
