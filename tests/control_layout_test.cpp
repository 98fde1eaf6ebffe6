// The control window's pure parts: the layout of the wall in it, the picture composed from the
// tiles' previews, and the status bar.
#include <gtest/gtest.h>

#include "master/control_view.h"
#include "wall_spec/control_layout.h"

namespace isowall {
namespace {

WallSpec grid(int columns, int rows, int w, int h, Bezels bezels = {}) {
    WallSpec s;
    s.columns = columns;
    s.rows = rows;
    s.tile_width_px = w;
    s.tile_height_px = h;
    s.bezel_px = bezels;
    return s;
}

Rgb pixel(const Image& img, int x, int y) {
    const std::size_t i = 4 * (static_cast<std::size_t>(y) * img.width + x);
    return {img.rgba[i], img.rgba[i + 1], img.rgba[i + 2]};
}

Image solid(int w, int h, Rgb c) {
    Image img;
    img.resize(w, h);
    fill_rect(img, {0, 0, w, h}, c);
    return img;
}

TEST(ControlLayout, A1x1WallOfOnePixelIsOnePixel) {
    const ControlLayout l = control_layout(grid(1, 1, 1, 1));
    EXPECT_EQ(l.mosaic.width, 1);
    EXPECT_EQ(l.mosaic.height, 1);
    EXPECT_EQ(l.scale, 1);
    ASSERT_EQ(l.tiles.size(), 1u);
    EXPECT_EQ(l.tiles[0].width, 1);
    EXPECT_EQ(preview_max_side(grid(1, 1, 1, 1)), 1);
}

TEST(ControlLayout, ASmallWallIsNeverEnlarged) {
    const ControlLayout l = control_layout(grid(2, 2, 160, 120));
    EXPECT_EQ(l.scale, 1) << l;
    EXPECT_EQ(l.mosaic.width, 320);
    EXPECT_EQ(l.mosaic.height, 240);
    EXPECT_EQ(l.tiles[3].x, 160);
    EXPECT_EQ(l.tiles[3].y, 120);
    EXPECT_EQ(preview_max_side(grid(2, 2, 160, 120)), 160);
}

TEST(ControlLayout, TheDissertationsWallFitsAndTilesShareEdges) {
    // 6x4 of 1024x768: 6144x3072 fits 1024 wide at 1/6.
    const ControlLayout l = control_layout(grid(6, 4, 1024, 768));
    EXPECT_EQ(l.mosaic.width, 1024) << l;
    EXPECT_EQ(l.mosaic.height, 512) << l;
    for (int t = 0; t < 24; ++t) {
        const PixelRect& r = l.tiles[static_cast<std::size_t>(t)];
        EXPECT_GE(r.width, 170) << t << " " << l;
        EXPECT_LE(r.width, 171) << t << " " << l;
        if (t % 6 < 5) {
            EXPECT_EQ(r.x + r.width, l.tiles[static_cast<std::size_t>(t + 1)].x) << t;
        }
        if (t / 6 < 3) {
            EXPECT_EQ(r.y + r.height, l.tiles[static_cast<std::size_t>(t + 6)].y) << t;
        }
    }
    EXPECT_EQ(l.tiles[23].x + l.tiles[23].width, 1024);
    EXPECT_EQ(l.tiles[23].y + l.tiles[23].height, 512);
    EXPECT_EQ(preview_max_side(grid(6, 4, 1024, 768)), 171);
}

TEST(ControlLayout, BezelsKeepTheirScaledWidthAndATallWallFitsItsHeight) {
    // walls/2x2-bezels.toml: 2048+80 x 1536+60 at scale 768/1596.
    const ControlLayout l = control_layout(grid(2, 2, 1024, 768, {40, 40, 30, 30}));
    EXPECT_EQ(l.mosaic.height, 768) << l;
    EXPECT_LE(l.mosaic.width, 1024) << l;
    const int gap = l.tiles[1].x - (l.tiles[0].x + l.tiles[0].width);
    EXPECT_GE(gap, 37) << l;  // 80 * 0.481 = 38.5
    EXPECT_LE(gap, 39) << l;
    const ControlLayout tall = control_layout(grid(1, 8, 1000, 1000));
    EXPECT_EQ(tall.mosaic.height, 768) << tall;
    EXPECT_EQ(tall.mosaic.width, 96) << tall;
}

TEST(ControlLayout, ADisabledTileHasAnEmptyRect) {
    WallSpec s = grid(2, 1, 100, 100);
    s.overrides.push_back({1, 0, true, 0, 0});
    const ControlLayout l = control_layout(s);
    EXPECT_EQ(l.tiles[1].width, 0);
    EXPECT_EQ(l.tiles[1].height, 0);
    EXPECT_EQ(l.tiles[0].width, 100);
}

TEST(ControlView, TilesWithoutAPreviewAreBlackAndBezelsGrey) {
    const ControlLayout l = control_layout(grid(2, 1, 40, 30, {5, 5, 0, 0}));  // a 10 px gap
    const Image img = compose_control(l, {}, {});
    const PixelSize size = control_window_size(l);
    ASSERT_EQ(img.width, size.width);
    ASSERT_EQ(img.height, size.height);
    EXPECT_EQ(size.height, 30 + kControlStatusHeight);
    EXPECT_EQ(pixel(img, 45, 15), kControlBezel);  // in the gap
    EXPECT_EQ(pixel(img, 10, 10), (Rgb{0, 0, 0}));
    EXPECT_EQ(pixel(img, 0, 10), kControlBezel);  // each tile's frame
    EXPECT_EQ(pixel(img, 60, 29), kControlBezel);
    EXPECT_EQ(pixel(img, 2, 40), kControlStatusBackground);
}

TEST(ControlView, EachPreviewIsScaledIntoItsTile) {
    const ControlLayout l = control_layout(grid(2, 2, 40, 30));
    // A preview of any size fills its rect: tile 1 sends a half-size one, tile 2 a 1x1.
    std::vector<Image> previews(4);
    previews[1] = solid(20, 15, {200, 0, 0});
    previews[2] = solid(1, 1, {0, 200, 0});
    const Image img = compose_control(l, previews, {});
    EXPECT_EQ(pixel(img, 41, 1), (Rgb{200, 0, 0}));  // inside tile 1, past its frame
    EXPECT_EQ(pixel(img, 78, 28), (Rgb{200, 0, 0}));
    EXPECT_EQ(pixel(img, 20, 45), (Rgb{0, 200, 0}));
    EXPECT_EQ(pixel(img, 20, 15), (Rgb{0, 0, 0}));  // tile 0: none yet
    EXPECT_EQ(pixel(img, 40, 15), kControlBezel);   // the seam between tiles 0 and 1
}

TEST(ControlView, TheStatusBarShowsTheIsovalue) {
    ControlStatus s{52.2, 0, 220, 3, true, "iso 52.2"};
    const std::vector<std::string> lines = status_lines(s);
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_EQ(lines[0], "iso 52.2  [0, 220]   frame 3 done   last: iso 52.2");
    EXPECT_NE(lines[1].find("esc quit"), std::string::npos);
    s.done = false;
    s.last.clear();
    EXPECT_EQ(status_lines(s)[0], "iso 52.2  [0, 220]   frame 3 running");
    s.clip = "x<99 z>40";
    EXPECT_EQ(status_lines(s)[0], "iso 52.2  [0, 220]   frame 3 running   clip x<99 z>40");
    s.clip.clear();
    s.time = "time 3/8 playing";
    EXPECT_EQ(status_lines(s)[0], "iso 52.2  [0, 220]   frame 3 running   time 3/8 playing");
    s.time.clear();
    s.surfaces = "52.2:#b17a65:0.3 160";
    EXPECT_EQ(status_lines(s)[0], "iso 52.2:#b17a65:0.3 160  [0, 220]   frame 3 running");
    s.surfaces.clear();
    // Drawn: text pixels appear in the bar, and a long line is cut at the window's edge.
    const ControlLayout l = control_layout(grid(1, 1, 60, 20));
    const Image img = compose_control(l, {}, lines);
    int lit = 0;
    for (int y = 20; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) lit += pixel(img, x, y) == kControlStatusText;
    EXPECT_GT(lit, 50);
}

TEST(ControlText, GlyphsHaveTheirShapeAndUnknownCharactersShowAsABox) {
    EXPECT_EQ(text_width("", 2), 0);
    EXPECT_EQ(text_width("iso", 1), 11);
    Image img = solid(8, 5, {0, 0, 0});
    draw_text(img, 0, 0, "1\x01", 1, {255, 255, 255});
    // '1': .#. ##. .#. .#. ###
    EXPECT_EQ(pixel(img, 0, 0), (Rgb{0, 0, 0}));
    EXPECT_EQ(pixel(img, 1, 0), (Rgb{255, 255, 255}));
    EXPECT_EQ(pixel(img, 0, 4), (Rgb{255, 255, 255}));
    EXPECT_EQ(pixel(img, 3, 2), (Rgb{0, 0, 0}));  // the gap between glyphs
    for (int y = 0; y < 5; ++y) EXPECT_EQ(pixel(img, 5, y), (Rgb{255, 255, 255})) << y;
    // Clipped, not out of bounds.
    draw_text(img, -5, 3, "88888", 3, {1, 2, 3});
}

}  // namespace
}  // namespace isowall
