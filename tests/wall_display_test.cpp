// The wall file's display keys (--windows): a tile's own display, else the wall's, else the
// rank's $DISPLAY; a malformed name is one line naming the field.
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "wall_spec/wall.h"

namespace isowall {
namespace {

TEST(WallDisplay, TileDisplaysComeFromTheTileElseTheWall) {
    const WallSpec w = parse_wall(R"(
        tiles = [2, 1]
        tile_size_px = [100, 50]
        display = "node7:0"
        [[tile]]
        column = 1
        row = 0
        display = ":0.1"
    )",
                                  "inline.toml");
    EXPECT_EQ(tile_display(w, 0), "node7:0");
    EXPECT_EQ(tile_display(w, 1), ":0.1");
    EXPECT_EQ(tile_display(parse_wall("tiles = [1, 1]\ntile_size_px = [8, 8]\n", "w"), 0), "");
}

TEST(WallDisplay, MalformedDisplaysNameTheField) {
    const std::string head = "tiles = [2, 2]\ntile_size_px = [1024, 768]\n";
    const struct {
        std::string text, field, mentions;
    } cases[] = {
        {"display = 0\n", "display", "expected an X display"},
        {"display = \"node7\"\n", "display", "got \"node7\""},
        {"display = \":0.x\"\n", "display", "got \":0.x\""},
        {"display = \"\"\n", "display", "got \"\""},
        {"[[tile]]\ncolumn = 0\nrow = 0\ndisplay = \"a b:0\"\n", "tile[0].display",
         "got \"a b:0\""},
    };
    for (const auto& c : cases) {
        try {
            parse_wall(head + c.text, "bad.toml");
            ADD_FAILURE() << "accepted " << c.text;
        } catch (const InputError& e) {
            const std::string msg = e.what();
            EXPECT_EQ(msg.rfind("bad.toml: " + c.field + ": ", 0), 0u) << msg;
            EXPECT_NE(msg.find(c.mentions), std::string::npos) << msg;
        }
    }
}

}  // namespace
}  // namespace isowall
