// Every file a wall run may write, checked before any frame: one error naming the option (or the
// script line) for each way a path can be unwritable.
#include <gtest/gtest.h>

#include <fstream>

#include "app/wall_outputs.h"
#include "core/error.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

namespace fs = std::filesystem;

// The error check_wall_outputs gives, or "".
std::string error_of(const WallOptions& o, const std::vector<ScriptLine>& script) {
    const WallSpec spec = parse_wall("tiles = [2, 1]\ntile_size_px = [64, 48]\n", "w.toml");
    try {
        check_wall_outputs(o, spec, script);
        return "";
    } catch (const InputError& e) {
        return e.what();
    }
}

TEST(WallOutputs, EveryOutputIsCheckedBeforeAnyFrame) {
    const auto dir = test::scratch_dir("wall_outputs");
    fs::create_directories(dir / "folder" / "inside");
    fs::create_directories(dir / "tiles" / "tile_1.png");
    fs::create_directory(dir / "good");
    fs::create_directories(dir / "shot.png" / "inside");
    fs::create_symlink("/dev/null", dir / "null.json");
    const fs::path d = dir;
    struct Case {
        const char* name;
        std::function<void(WallOptions&)> set;
        std::string script;
        std::string mentions;  // empty: fine
    };
    const std::vector<Case> cases = {
        {"fine", [&](WallOptions& o) { o.out = d / "m.png"; }, "snapshot a\nsnapshot a\n", ""},
        {"out missing folder", [&](WallOptions& o) { o.out = d / "no" / "m.png"; }, "", "--out"},
        {"out is a folder", [&](WallOptions& o) { o.out = d / "folder"; }, "", "--out"},
        {"out is a device", [&](WallOptions& o) { o.out = "/dev/null"; }, "", "--out"},
        {"tiles-out missing", [&](WallOptions& o) { o.tiles_out = d / "nope"; }, "", "--tiles-out"},
        {"tiles-out a file", [&](WallOptions& o) { o.tiles_out = d / "good" / "x"; }, "",
         "--tiles-out"},
        {"a tile image is a folder", [&](WallOptions& o) { o.tiles_out = d / "tiles"; }, "",
         "tile_1.png: --tiles-out"},
        {"trace missing folder", [&](WallOptions& o) { o.trace = d / "no" / "t"; }, "", "--trace"},
        {"trace on a device", [&](WallOptions& o) { o.trace = d / "null"; }, "",
         "null.json: --trace"},
        {"snapshot is a folder", [&](WallOptions& o) { o.out = d / "m.png"; }, "\nsnapshot shot\n",
         "s.txt:2: snapshot"},
        {"snapshot is the mosaic", [&](WallOptions& o) { o.out = d / "m.png"; }, "snapshot m\n",
         "also the file of --out"},
    };
    for (const Case& c : cases) {
        WallOptions o;
        o.out = d / "m.png";
        o.script = "s.txt";
        c.set(o);
        const std::string e = error_of(o, parse_script(c.script, "s.txt"));
        if (c.mentions.empty())
            EXPECT_EQ(e, "") << c.name;
        else
            EXPECT_NE(e.find(c.mentions), std::string::npos) << c.name << ": " << e;
    }
    // Nothing was created by checking.
    EXPECT_TRUE(fs::is_empty(dir / "good"));
}

}  // namespace
}  // namespace isowall
