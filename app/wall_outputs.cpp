#include "app/wall_outputs.h"

#include <filesystem>
#include <set>
#include <string>

#include "core/error.h"

namespace isowall {

std::vector<OutputPath> wall_outputs(const WallOptions& o, const WallSpec& spec,
                                     const std::vector<ScriptLine>& script) {
    namespace fs = std::filesystem;
    std::vector<OutputPath> out{{"--out", o.out}};
    if (!o.tiles_out.empty())
        for (int tile = 0; tile < tile_count(spec); ++tile)
            if (tile_enabled(spec, tile))
                out.push_back({"--tiles-out",
                               fs::path(o.tiles_out) / ("tile_" + std::to_string(tile) + ".png")});
    if (!o.trace.empty()) {
        out.push_back({"--trace", o.trace + ".json"});
        out.push_back({"--trace", o.trace + ".csv"});
    }
    // Snapshots go beside the mosaic; a name given twice is written twice, so it is listed once.
    std::set<std::string> seen;
    const std::string file = o.script.empty() ? std::string("--script") : o.script;
    for (const ScriptLine& l : script)
        if (const auto* s = std::get_if<SnapshotCmd>(&l.command); s && seen.insert(s->name).second)
            out.push_back({clip_source(file + ":" + std::to_string(l.line)) + ": snapshot",
                           fs::path(o.out).parent_path() / (s->name + ".png")});
    return out;
}

void check_wall_outputs(const WallOptions& o, const WallSpec& spec,
                        const std::vector<ScriptLine>& script) {
    if (!o.tiles_out.empty() && !std::filesystem::is_directory(o.tiles_out))
        throw InputError(o.tiles_out, "--tiles-out", "expected an existing folder");
    check_outputs(wall_outputs(o, spec, script));
}

}  // namespace isowall
