// Writes the wire harness's seed corpus: one encoded message of every type, each with a value
// other than the default in its fields, as the harness reads them (the tag byte, then the
// message). Run: fuzz_wire_seeds fuzz/corpus/wire (the files there are its output, committed).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "wall_protocol/protocol.h"

namespace {

using namespace isowall;

FrameView sample_view() {
    FrameView v;
    v.camera.eye = {1, 2, 3};
    v.camera.projection = Projection::orthographic;
    v.frustum.left = -0.5f;
    v.width = 4;
    v.height = 3;
    v.iso = 105.5;
    return v;
}

std::vector<Message> samples() {
    const FrameView view = sample_view();
    ImageMsg image{7, 2, 1, {1, 2, 3, 4, 5, 6, 7, 8}, {0.5f, 1.0f}};
    ImageMsg no_depth{8, 1, 1, {9, 9, 9, 255}, {}};
    TileResultMsg result;
    result.host = "node-3";
    result.cpu_s = 1.5;
    result.rays = 1000;
    result.jobs_own = 3;
    result.curve = {{0.25, 12, 3.5}};
    result.spans = {{2, 100.0, 0.5, 0.25}, {6, 101.0, 0.1, 0.1}};
    JobMsg job{9, 4, 2, 2, Band::fine, view, {1, 0, 2, 3}};
    JobDoneMsg done{9, 4, 500, 3, 40, 0.1, 0.9, 100.5, 100.6, 96};
    RegionMsg region{9, 4, 1, {1, 1, 2, 1}, 0.9, {1, 2, 3, 4, 5, 6, 7, 8}, {0.25f, 0.75f}};
    PreviewMsg preview{9, 2, 1, {10, 20, 30, 40, 50, 60}};
    return {
        TileHelloMsg{"tile-1", 1, false},
        TileHelloMsg{"tile-1", 16, true},
        ViewMsg{5, view},
        ViewMsg{6, view, {{40, {177, 122, 101}, 0.3f, true}, {105.5, {241, 214, 145}, 1, true}}},
        ProgressMsg{5, 12345, 0.5},
        SnapshotMsg{},
        image,
        no_depth,
        QuitMsg{},
        result,
        ReleaseMsg{},
        StartMsg{},
        AliveMsg{},
        job,
        done,
        region,
        LandedMsg{9, 4},
        preview,
        StoreAskMsg{StorePart::chunk, 42},
        StoreMetaMsg{true, R"({"zarr_format": 2})", R"({"isowall": {}})", 4096, 100},
        StorePartMsg{StorePart::chunk, 42, {std::byte{0x28}, std::byte{0xb5}}},
        CurveAskMsg{9},
        CurveMsg{{9, 100, {{0.5, 40, 1.25}, {0.75, 100, 0}}}},
        FailedMsg{false, "0/1/1/0: cannot decompress"},
        LostMsg{3}};  // new last
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: fuzz_wire_seeds FOLDER\n");
        return 2;
    }
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    int n = 0;
    for (const Message& m : samples()) {
        const Tag tag = tag_of(m);
        const std::vector<std::byte> bytes = encode(m);
        const auto name = std::string(to_string(tag)) + "-" + std::to_string(n++);
        std::ofstream out(dir / name, std::ios::binary);
        out.put(static_cast<char>(static_cast<std::int8_t>(tag)));
        out.write(reinterpret_cast<const char*>(bytes.data()),
                  static_cast<std::streamsize>(bytes.size()));
        if (!out) {
            std::fprintf(stderr, "fuzz_wire_seeds: cannot write %s\n", (dir / name).c_str());
            return 1;
        }
    }
    std::printf("fuzz_wire_seeds: %d messages in %s\n", n, dir.c_str());
    return 0;
}
