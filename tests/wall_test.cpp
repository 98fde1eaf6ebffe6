// Wall files and wall geometry: every example parses, tiles cover the virtual screen as the
// bezels say, tile frusta agree with the wall frustum, ranks map to tiles and back, and each kind
// of bad input names the file and the field.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <set>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/error.h"
#include "wall_spec/wall.h"

namespace isowall {
namespace {

const std::filesystem::path kWalls = std::filesystem::path(ISOWALL_SOURCE_DIR) / "walls";

WallSpec grid(int columns, int rows, Bezels bezels = {}) {
    WallSpec w;
    w.columns = columns;
    w.rows = rows;
    w.bezel_px = bezels;
    return w;
}

// Pixel coordinates (x right, y down) of p on a screen of w x h seen through `proj`.
glm::dvec2 to_pixel(const glm::mat4& proj, const glm::mat4& view, glm::vec3 p, int w, int h) {
    const glm::vec4 c = proj * view * glm::vec4(p, 1.0f);
    const glm::dvec2 ndc(c.x / c.w, c.y / c.w);
    return {(ndc.x * 0.5 + 0.5) * w, (0.5 - ndc.y * 0.5) * h};
}

bool contains(const PixelRect& r, glm::dvec2 p) {
    return p.x >= r.x && p.x < r.x + r.width && p.y >= r.y && p.y < r.y + r.height;
}

TEST(Wall, EveryExampleFileParses) {
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(kWalls)) {
        if (entry.path().extension() != ".toml") continue;
        ++files;
        try {
            const WallSpec w = load_wall(entry.path());
            EXPECT_GE(rank_count(w), 2) << entry.path() << " " << w;
        } catch (const InputError& e) {
            ADD_FAILURE() << e.what();
        }
    }
    EXPECT_GE(files, 6) << "in " << kWalls;
}

TEST(Wall, ExampleFilesHoldWhatTheirCommentsSay) {
    const WallSpec big = load_wall(kWalls / "6x4.toml");
    EXPECT_EQ(tile_count(big), 24);
    EXPECT_EQ(rank_count(big), 25);
    EXPECT_EQ(virtual_screen_size(big).width, 6 * 1024);
    EXPECT_EQ(virtual_screen_size(big).height, 4 * 768);

    const WallSpec overlap = load_wall(kWalls / "3x2-overlap.toml");
    EXPECT_EQ(overlap.bezel_px.left, -64) << overlap;
    EXPECT_EQ(overlap.rank_order, RankOrder::serpentine);

    // 6.3 mm at a 0.63 mm pitch is 10 px on every side, 20 px between neighbours.
    const WallSpec phys = load_wall(kWalls / "2x2-physical.toml");
    ASSERT_TRUE(phys.physical.has_value());
    EXPECT_EQ(phys.bezel_px.left, 10) << phys;
    EXPECT_EQ(phys.bezel_px.bottom, 10) << phys;
    EXPECT_EQ(virtual_screen_size(phys).width, 2 * 1920 + 20);
    EXPECT_EQ(virtual_screen_size(phys).height, 2 * 1080 + 20);
    ASSERT_TRUE(phys.physical->viewer_mm.has_value());
    EXPECT_DOUBLE_EQ(phys.physical->viewer_mm->z, 2000.0);
    EXPECT_EQ(phys.rank_order, RankOrder::column_major);
}

TEST(Wall, OneByOneIsTheWholeScreen) {
    const WallSpec w = load_wall(kWalls / "1x1.toml");
    const PixelSize s = virtual_screen_size(w);
    EXPECT_EQ(s.width, 1024);
    EXPECT_EQ(s.height, 768);
    const PixelRect r = tile_rect(w, 0);
    EXPECT_EQ(r.x, 0);
    EXPECT_EQ(r.y, 0);
    EXPECT_EQ(r.width, 1024);
    EXPECT_EQ(r.height, 768);
    EXPECT_EQ(rank_count(w), 2);
    EXPECT_EQ(tile_of_rank(w, kMasterRank), kNoTile);
    EXPECT_EQ(tile_of_rank(w, 1), 0);
    EXPECT_EQ(rank_of_tile(w, 0), 1);
    EXPECT_THROW(tile_of_rank(w, 2), std::out_of_range);
    EXPECT_THROW(rank_of_tile(w, 1), std::out_of_range);

    // The one tile's frustum is the wall's, exactly.
    Frustum wall;
    wall.left = -0.4f;
    wall.right = 0.4f;
    wall.bottom = -0.3f;
    wall.top = 0.3f;
    const Frustum f = tile_frustum(wall, w, 0);
    EXPECT_EQ(f.left, wall.left);
    EXPECT_EQ(f.right, wall.right);
    EXPECT_EQ(f.bottom, wall.bottom);
    EXPECT_EQ(f.top, wall.top);
}

// Counts how many tiles cover each virtual-screen pixel.
std::vector<int> coverage(const WallSpec& w) {
    const PixelSize s = virtual_screen_size(w);
    std::vector<int> count(size_t(s.width) * s.height, 0);
    for (int t = 0; t < tile_count(w); ++t) {
        const PixelRect r = tile_rect(w, t);
        for (int y = r.y; y < r.y + r.height; ++y)
            for (int x = r.x; x < r.x + r.width; ++x) {
                EXPECT_TRUE(x >= 0 && x < s.width && y >= 0 && y < s.height)
                    << "tile " << t << " " << r << " leaves the screen";
                if (x >= 0 && x < s.width && y >= 0 && y < s.height)
                    ++count[size_t(y) * s.width + x];
            }
    }
    return count;
}

TEST(Wall, TilesWithoutBezelsCoverTheScreenExactlyOnce) {
    WallSpec w = grid(2, 2);
    w.tile_width_px = 64;
    w.tile_height_px = 48;
    EXPECT_EQ(virtual_screen_size(w).width, 128);
    EXPECT_EQ(virtual_screen_size(w).height, 96);
    const std::vector<int> count = coverage(w);
    for (size_t i = 0; i < count.size(); ++i)
        ASSERT_EQ(count[i], 1) << "pixel " << i % 128 << "," << i / 128 << " of " << w;
}

TEST(Wall, BezelGapsAreTheBezelWidths) {
    WallSpec w = grid(3, 2, {.left = 3, .right = 5, .top = 2, .bottom = 4});
    w.tile_width_px = 20;
    w.tile_height_px = 10;
    const PixelSize s = virtual_screen_size(w);
    EXPECT_EQ(s.width, 3 * 20 + 2 * 8);
    EXPECT_EQ(s.height, 2 * 10 + 1 * 6);
    for (int row = 0; row < w.rows; ++row)
        for (int col = 0; col + 1 < w.columns; ++col) {
            const PixelRect a = tile_rect(w, tile_index(w, col, row));
            const PixelRect b = tile_rect(w, tile_index(w, col + 1, row));
            EXPECT_EQ(b.x - (a.x + a.width), 8) << a << " " << b;
            EXPECT_EQ(a.y, b.y);
        }
    const PixelRect top = tile_rect(w, tile_index(w, 1, 0));
    const PixelRect below = tile_rect(w, tile_index(w, 1, 1));
    EXPECT_EQ(below.y - (top.y + top.height), 6) << top << " " << below;
    // No pixel is covered twice, and exactly the bezel pixels are covered by none.
    const std::vector<int> count = coverage(w);
    int uncovered = 0;
    for (int c : count) {
        EXPECT_LE(c, 1);
        uncovered += c == 0;
    }
    EXPECT_EQ(uncovered, s.width * s.height - 6 * 20 * 10);
}

TEST(Wall, ProjectorOverlapIsShared) {
    const WallSpec w = load_wall(kWalls / "3x2-overlap.toml");
    const PixelSize s = virtual_screen_size(w);
    EXPECT_EQ(s.width, 3 * 1400 - 2 * 128);
    EXPECT_EQ(s.height, 2 * 1050 - 96);
    const PixelRect a = tile_rect(w, tile_index(w, 0, 0));
    const PixelRect b = tile_rect(w, tile_index(w, 1, 0));
    const PixelRect c = tile_rect(w, tile_index(w, 0, 1));
    EXPECT_EQ(a.x + a.width - b.x, 128) << a << " " << b;
    EXPECT_EQ(a.y + a.height - c.y, 96) << a << " " << c;
    // The last tile ends exactly at the screen's corner.
    const PixelRect last = tile_rect(w, tile_count(w) - 1);
    EXPECT_EQ(last.x + last.width, s.width);
    EXPECT_EQ(last.y + last.height, s.height);
}

// A point lands on the same virtual-screen pixel through the wall frustum and through the
// frustum of any tile that shows it, so lines stay straight across bezels and overlaps.
TEST(Wall, TileFrustaAgreeWithTheWallFrustum) {
    WallSpec skewed = grid(3, 2, {.left = 7, .right = 11, .top = 5, .bottom = 2});
    skewed.overrides.push_back({.column = 2, .row = 1, .offset_x_px = 13, .offset_y_px = -9});
    const std::vector<std::pair<std::string, WallSpec>> walls = {
        {"2x2", load_wall(kWalls / "2x2.toml")},
        {"2x2-bezels", load_wall(kWalls / "2x2-bezels.toml")},
        {"3x2-overlap", load_wall(kWalls / "3x2-overlap.toml")},
        {"2x2-physical", load_wall(kWalls / "2x2-physical.toml")},
        {"skewed", skewed}};
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (const auto& [name, w] : walls)
        for (Projection proj : {Projection::perspective, Projection::orthographic}) {
            const PixelSize s = virtual_screen_size(w);
            Camera cam;
            cam.projection = proj;
            const Frustum wall = cam.frustum(float(s.width) / float(s.height));
            const glm::mat4 view = cam.view();
            // Points anywhere in the wall's view volume: unproject random screen positions.
            const glm::mat4 unproject = glm::inverse(wall.matrix() * view);
            int hits = 0;
            for (int i = 0; i < 200; ++i) {
                const glm::vec4 h =
                    unproject * glm::vec4(u(rng) * 2 - 1, u(rng) * 2 - 1, u(rng) * 1.8f - 0.9f, 1);
                const glm::vec3 p = glm::vec3(h) / h.w;
                const glm::dvec2 on_wall = to_pixel(wall.matrix(), view, p, s.width, s.height);
                for (int t = 0; t < tile_count(w); ++t) {
                    const PixelRect r = tile_rect(w, t);
                    if (!contains(r, on_wall)) continue;
                    const Frustum f = tile_frustum(wall, w, t);
                    const glm::dvec2 on_tile =
                        to_pixel(f.matrix(), view, p, r.width, r.height) + glm::dvec2(r.x, r.y);
                    EXPECT_NEAR(on_tile.x, on_wall.x, 0.02) << name << " tile " << t << " " << r;
                    EXPECT_NEAR(on_tile.y, on_wall.y, 0.02) << name << " tile " << t << " " << r;
                    ++hits;
                }
            }
            EXPECT_GT(hits, 150) << name << ": too few points landed on a tile to test anything";
        }
}

TEST(Wall, RanksAndTilesRoundTripInEveryOrder) {
    WallSpec holes = grid(4, 3);
    holes.overrides.push_back({.column = 1, .row = 0, .disabled = true});
    holes.overrides.push_back({.column = 3, .row = 2, .disabled = true});
    for (RankOrder order : {RankOrder::row_major, RankOrder::column_major, RankOrder::serpentine})
        for (WallSpec w : {grid(6, 4), grid(3, 2), grid(1, 5), grid(1, 1), holes}) {
            w.rank_order = order;
            std::set<int> seen;
            for (int rank = 1; rank < rank_count(w); ++rank) {
                const int tile = tile_of_rank(w, rank);
                ASSERT_GE(tile, 0) << w << " rank " << rank;
                EXPECT_TRUE(tile_enabled(w, tile)) << w << " rank " << rank;
                EXPECT_EQ(rank_of_tile(w, tile), rank) << w;
                EXPECT_TRUE(seen.insert(tile).second) << w << " tile " << tile << " twice";
            }
            for (int t = 0; t < tile_count(w); ++t)
                EXPECT_EQ(seen.count(t) == 1, tile_enabled(w, t)) << w << " tile " << t;
            EXPECT_EQ(tile_of_rank(w, kMasterRank), kNoTile);
            EXPECT_THROW(tile_of_rank(w, rank_count(w)), std::out_of_range) << w;
            EXPECT_THROW(tile_of_rank(w, -1), std::out_of_range) << w;
        }
    EXPECT_EQ(rank_of_tile(holes, tile_index(holes, 1, 0)), kNoRank);
    EXPECT_EQ(rank_count(holes), 11);
}

TEST(Wall, RankOrdersFollowTheirNames) {
    WallSpec w = grid(3, 2);
    // Ranks 1..6 in the tile order each name promises (tiles numbered row-major).
    const std::vector<std::pair<RankOrder, std::vector<int>>> expected = {
        {RankOrder::row_major, {0, 1, 2, 3, 4, 5}},
        {RankOrder::column_major, {0, 3, 1, 4, 2, 5}},
        {RankOrder::serpentine, {0, 1, 2, 5, 4, 3}}};
    for (const auto& [order, tiles] : expected) {
        w.rank_order = order;
        for (int rank = 1; rank <= 6; ++rank)
            EXPECT_EQ(tile_of_rank(w, rank), tiles[rank - 1])
                << to_string(order) << " rank " << rank;
    }
}

TEST(Wall, TileOverridesParse) {
    const WallSpec w = parse_wall(R"(
        tiles = [3, 2]
        tile_size_px = [100, 50]
        bezel_px = 4
        [[tile]]
        column = 1
        row = 0
        disabled = true
        [[tile]]
        column = 2
        row = 1
        offset_px = [3, -2]
    )",
                                  "inline.toml");
    EXPECT_EQ(w.bezel_px.left, 4);
    EXPECT_EQ(w.bezel_px.top, 4);
    EXPECT_FALSE(tile_enabled(w, 1));
    EXPECT_EQ(rank_count(w), 6);
    EXPECT_EQ(tile_of_rank(w, 2), 2);  // tile 1 is skipped
    const PixelRect r = tile_rect(w, 5);
    EXPECT_EQ(r.x, 2 * 108 + 3) << r;
    EXPECT_EQ(r.y, 1 * 58 - 2) << r;
    EXPECT_EQ(tile_display(w, 0), "") << "no display key: each rank's $DISPLAY";
}

struct BadWall {
    std::string name;
    std::string text;
    std::string field;     // the message must start with "bad.toml: FIELD: "
    std::string mentions;  // and contain this
};

std::vector<BadWall> bad_walls() {
    const std::string size = "tile_size_px = [1024, 768]\n";
    return {
        {"missing tiles", size, "tiles", "missing"},
        {"missing size", "tiles = [2, 2]\n", "tile_size_px", "missing"},
        {"zero rows", "tiles = [6, 0]\n" + size, "tiles",
         "expected two positive integers (columns, rows), got [6, 0]"},
        {"zero width", "tiles = [2, 2]\ntile_size_px = [0, 768]\n", "tile_size_px", "got [0, 768]"},
        {"one number", "tiles = [2]\n" + size, "tiles", "got [2]"},
        {"wrong type", "tiles = \"2x2\"\n" + size, "tiles", "got \"2x2\""},
        {"float tiles", "tiles = [2.0, 2]\n" + size, "tiles", "got [2.0, 2]"},
        {"unknown key", "tiles = [2, 2]\n" + size + "bezels_px = 4\n", "bezels_px", "unknown key"},
        {"unknown bezel side", "tiles = [2, 2]\n" + size + "bezel_px = { lft = 4 }\n",
         "bezel_px.lft", "unknown key"},
        {"bezel type", "tiles = [2, 2]\n" + size + "bezel_px = 4.5\n", "bezel_px", "got 4.5"},
        {"bad rank order", "tiles = [2, 2]\n" + size + "rank_order = \"snake\"\n", "rank_order",
         "got \"snake\""},
        {"overlap past tile",
         "tiles = [2, 2]\n" + size + "bezel_px = { left = -600, right = -600 }\n", "bezel_px",
         "less than the tile width 1024"},
        {"physical without size", "tiles = [2, 2]\n" + size + "[physical]\nbezel_mm = 5\n",
         "physical.tile_size_mm", "missing"},
        {"physical unknown",
         "tiles = [2, 2]\n" + size + "[physical]\ntile_size_mm = [400, 300]\nviewer = [0, 0, 1]\n",
         "physical.viewer", "unknown key"},
        {"viewer behind",
         "tiles = [2, 2]\n" + size +
             "[physical]\ntile_size_mm = [400, 300]\nviewer_mm = [0, 0, -1]\n",
         "physical.viewer_mm", "z > 0"},
        {"bezels twice",
         "tiles = [2, 2]\n" + size +
             "bezel_px = 2\n[physical]\ntile_size_mm = [400, 300]\nbezel_mm = 5\n",
         "physical.bezel_mm", "conflicts with bezel_px"},
        {"tile out of range", "tiles = [2, 2]\n" + size + "[[tile]]\ncolumn = 2\nrow = 0\n",
         "tile[0].column", "expected an integer in [0, 1], got 2"},
        {"tile without row", "tiles = [2, 2]\n" + size + "[[tile]]\ncolumn = 1\n", "tile[0].row",
         "missing"},
        {"tile unknown",
         "tiles = [2, 2]\n" + size + "[[tile]]\ncolumn = 1\nrow = 1\nhidden = true\n",
         "tile[0].hidden", "unknown key"},
        {"tile twice",
         "tiles = [1, 1]\n" + size +
             "[[tile]]\ncolumn = 0\nrow = 0\n[[tile]]\ncolumn = 0\nrow = 0\n",
         "tile[1].column", "given twice"},
        {"all disabled",
         "tiles = [1, 1]\n" + size + "[[tile]]\ncolumn = 0\nrow = 0\ndisabled = true\n", "tile",
         "every tile is disabled"},
        {"syntax error", "tiles = [2, 2]\ntile_size_px = [1024, 768\n", "line 2, column",
         "TOML syntax"},
        // Found by fuzz/fuzz_wall.cpp, or written beside it: walls whose numbers parse but whose
        // geometry would not fit an image message or an int.
        {"tile past a message", "tiles = [4, 4]\ntile_size_px = [1399, 101050]\n", "tile_size_px",
         "in [1, 32768] (width, height), got [1399, 101050]"},
        {"screen past an int", "tiles = [100000, 1]\ntile_size_px = [32768, 1]\n", "tiles",
         "the virtual screen would be 3276800000x1 px"},
        {"bezels past an int", "tiles = [2000, 1]\n" + size + "bezel_px = 1000000\n", "tiles",
         "expected at most 131072 a side"},
        {"bezel_mm past an int",
         "tiles = [2, 2]\n" + size + "[physical]\ntile_size_mm = [400, 300]\nbezel_mm = 1e300\n",
         "physical.bezel_mm", "each in [-1e6, 1e6], got 1e+300"},
        {"tiny pitch",
         "tiles = [2, 2]\n" + size + "[physical]\ntile_size_mm = [1e-320, 300]\nbezel_mm = 1\n",
         "physical.tile_size_mm", "expected two numbers in [1e-3, 1e6]"},
        {"offset past a million",
         "tiles = [2, 2]\n" + size + "[[tile]]\ncolumn = 0\nrow = 0\noffset_px = [2147483647, 0]\n",
         "tile[0].offset_px", "got [2147483647, 0]"},
        // Within the old [-1e6, 1e6] but past the tile: once a grey tile and exit 0.
        {"offset past its tile",
         "tiles = [2, 2]\n" + size + "[[tile]]\ncolumn = 0\nrow = 0\noffset_px = [1000000, 0]\n",
         "tile[0].offset_px", "within the tile's size"},
    };
}

TEST(Wall, MalformedInputNamesFileAndField) {
    for (const BadWall& c : bad_walls()) {
        try {
            const WallSpec w = parse_wall(c.text, "bad.toml");
            ADD_FAILURE() << c.name << ": accepted " << w << " from\n" << c.text;
        } catch (const InputError& e) {
            const std::string msg = e.what();
            EXPECT_EQ(msg.rfind("bad.toml: " + c.field, 0), 0u) << c.name << ": " << msg;
            EXPECT_NE(msg.find(c.mentions), std::string::npos) << c.name << ": " << msg;
            EXPECT_EQ(msg.find('\n'), std::string::npos) << c.name << ": not one line: " << msg;
        }
    }
}

TEST(Wall, MissingFileNamesThePath) {
    try {
        load_wall(kWalls / "no-such-wall.toml");
        ADD_FAILURE() << "no error for a missing file";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no-such-wall.toml"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace isowall
