// What the wall's page (wall --http) must show for a wall mosaic: each tile cut from the wall's
// full-size mosaic (--out, or a snapshot), shrunk as a tile shrinks its preview, placed as the
// control window places it (the same pure functions: make_preview, compose_mosaic). For
// web/test/e2e_wall.mjs, which compares the page's canvas with it.
//   isowall_test_page_mosaic WALL.toml MOSAIC.png OUT.png
#include <cstdio>
#include <exception>

#include "core/image_ops.h"
#include "core/preview.h"
#include "files/image_io.h"
#include "master/control_view.h"
#include "wall_spec/control_layout.h"
#include "wall_spec/wall.h"

int main(int argc, char** argv) {
    using namespace isowall;
    if (argc != 4) {
        std::fprintf(stderr, "usage: isowall_test_page_mosaic WALL.toml MOSAIC.png OUT.png\n");
        return 2;
    }
    try {
        const WallSpec spec = load_wall(argv[1]);
        const Image mosaic = read_image(argv[2]);
        std::vector<Image> previews;
        for (int t = 0; t < tile_count(spec); ++t)
            previews.push_back(preview_image(
                make_preview(crop(mosaic, tile_rect(spec, t)), 1, preview_max_side(spec))));
        write_image(argv[3], compose_mosaic(control_layout(spec), previews));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "isowall_test_page_mosaic: %s\n", e.what());
        return 1;
    }
    return 0;
}
