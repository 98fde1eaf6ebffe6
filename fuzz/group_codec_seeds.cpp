// Writes the group_codec harness's seed corpus: three small groups built by hand (a
// tetrahedron, a 4 x 4 grid of vertices with one vertex no triangle uses, and an empty group),
// each in every mesh encoding, a few hundred bytes a file; and small propagation passes of the
// phantom as `cells` (which needs the volume). With a second folder, the cell_body harness's
// seeds too: those passes' cells bodies (no zstd) after their isovalue, at levels 0 and 2 and
// as a refinement.
// Run: fuzz_group_codec_seeds fuzz/corpus/group_codec fuzz/corpus/cell_body (the files there are
// its output, committed).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "remote/cell_codec.h"
#include "remote/group_codec.h"
#include "remote/sample_groups.h"
#include "volume/phantom.h"

namespace {

using namespace isowall;
using namespace isowall::remote;

Group header(std::uint32_t id, int level, double iso, bool refinement) {
    Group g;
    g.id = id;
    g.seed = {4, -5, 6};
    g.level = level;
    g.iso = iso;
    g.refinement = refinement;
    return g;
}

Group tetrahedron() {
    Group g = header(7, 0, 105.5, false);
    g.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    g.mesh.normals = {{-0.577f, -0.577f, -0.577f}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    g.mesh.indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    return g;
}

// A bumpy 4 x 4 patch (18 triangles) at a voxel-like scale, plus one vertex no triangle uses.
Group grid() {
    Group g = header(12, 2, -40.25, true);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            g.mesh.positions.push_back({10.0f + 0.5f * x, 20.0f + 0.5f * y, 3.0f + 0.1f * (x ^ y)});
            g.mesh.normals.push_back({0.1f * x, -0.1f * y, 1});
        }
    for (std::uint32_t y = 0; y < 3; ++y)
        for (std::uint32_t x = 0; x < 3; ++x) {
            const std::uint32_t i = 4 * y + x;
            g.mesh.indices.insert(g.mesh.indices.end(), {i, i + 1, i + 5, i, i + 5, i + 4});
        }
    g.mesh.positions.push_back({100, 100, 100});
    g.mesh.normals.push_back({0, 0, -1});
    return g;
}

bool write(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
    if (!out) std::fprintf(stderr, "fuzz_group_codec_seeds: cannot write %s\n", path.c_str());
    return static_cast<bool>(out);
}

}  // namespace

// Small passes of the phantom: cells, meta-cells of level 2, and a refinement of one of those.
std::vector<std::pair<std::string, Group>> phantom_passes(const Volume& p) {
    std::vector<std::pair<std::string, Group>> out;
    out.emplace_back("phantom-cells", sample_groups(p, kPhantomSkinIso, 4, 12).at(0));
    const Group coarse = sample_groups(p, kPhantomSkinIso, 4, 6, uniform_levels(2)).at(0);
    out.emplace_back("phantom-level2", coarse);
    auto ex = make_surface_extractor(p);
    ex->begin_frame(kPhantomSkinIso, uniform_levels(2));
    out.emplace_back("phantom-refinement", ex->refine(coarse.cells.at(0), 2, 3, {}));
    return out;
}

int main(int argc, char** argv) {
    if (argc != 2 && argc != 3) {
        std::fprintf(stderr, "usage: fuzz_group_codec_seeds FOLDER [CELL_BODY_FOLDER]\n");
        return 2;
    }
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    const std::pair<const char*, Group> groups[] = {
        {"tetrahedron", tetrahedron()}, {"grid", grid()}, {"empty", header(1, 30, 0, false)}};
    int n = 0;
    for (const auto& [name, group] : groups)
        for (GroupEncoding e : kAllGroupEncodings) {
            if (e == GroupEncoding::cells) continue;  // needs a volume: the phantom's below
            std::string file = std::string(to_string(e)) + "-" + name;
            std::replace(file.begin(), file.end(), '+', '_');  // compact+zstd: a plain name
            if (!write(dir / file, encode_group(group, e))) return 1;
            ++n;
        }
    const Volume phantom = make_phantom();
    const auto passes = phantom_passes(phantom);
    for (const auto& [name, group] : passes) {
        if (!write(dir / ("cells-" + name), encode_group(group, GroupEncoding::cells, 0, &phantom)))
            return 1;
        ++n;
    }
    std::printf("fuzz_group_codec_seeds: %d groups in %s\n", n, dir.c_str());
    if (argc == 3) {
        const std::filesystem::path bodies = argv[2];
        std::filesystem::create_directories(bodies);
        for (const auto& [name, group] : passes) {
            const auto body = encode_cell_body(group, phantom);
            if (!body) return 1;
            std::vector<std::uint8_t> bytes(sizeof(double));
            std::memcpy(bytes.data(), &group.iso, sizeof(double));
            bytes.insert(bytes.end(), body->begin(), body->end());
            if (!write(bodies / name, bytes)) return 1;
        }
        std::printf("fuzz_group_codec_seeds: %zu cells bodies in %s\n", passes.size(),
                    bodies.c_str());
    }
    return 0;
}
