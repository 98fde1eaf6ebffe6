// Another tool's Zarr array streamed a slab at a time (readers/zarr_reader.h: zarr_planes), as
// `isowall import` and the re-chunked copy (cli/rechunked_store.h) read it: for chunkings whose
// rows along z are shorter than, equal to and longer than the slabs asked for, in C and F order,
// of either byte order, with a chunk left out as the fill value, the planes streamed are the
// voxels read whole; a chunk that fails to decode mid-stream is an error naming it.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "readers/plane_stack.h"
#include "readers/read_volume.h"
#include "readers/zarr_reader.h"
#include "tests/plane_stream_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

namespace fs = std::filesystem;

struct ArrayShape {
    int x = 11, y = 9, z = 13;   // voxels
    int cx = 4, cy = 5, cz = 3;  // a chunk
    bool fortran = false, big_endian = false;
    std::vector<std::string> left_out;  // chunk keys not written
};

std::uint16_t value(int x, int y, int z) {
    return static_cast<std::uint16_t>(x + 17 * y + 301 * z);
}

// An uncompressed Zarr v2 array of uint16 `value`s, fill value 7, written chunk by chunk.
fs::path write_array(const std::string& name, const ArrayShape& s) {
    // A folder of its own (scratch_dir empties it): tests run at once must not share one.
    const fs::path dir = test::scratch_dir("zarr_stream_" + name);
    std::ofstream(dir / ".zarray")
        << R"({"zarr_format": 2, "shape": [)" << s.z << ", " << s.y << ", " << s.x
        << R"(], "chunks": [)" << s.cz << ", " << s.cy << ", " << s.cx << R"(], "dtype": ")"
        << (s.big_endian ? ">u2" : "<u2") << R"(", "compressor": null, "fill_value": 7, )"
        << R"("order": ")" << (s.fortran ? "F" : "C") << R"(", "filters": null})";
    for (int bz = 0; bz * s.cz < s.z; ++bz)
        for (int by = 0; by * s.cy < s.y; ++by)
            for (int bx = 0; bx * s.cx < s.x; ++bx) {
                const std::string key =
                    std::to_string(bz) + "." + std::to_string(by) + "." + std::to_string(bx);
                if (std::find(s.left_out.begin(), s.left_out.end(), key) != s.left_out.end())
                    continue;
                std::string bytes;
                for (int i = 0; i < s.cx * s.cy * s.cz; ++i) {
                    // C order: x fastest; F order: z fastest.
                    const int fast = s.fortran ? s.cz : s.cx, mid = s.cy;
                    const int a = i % fast, b = (i / fast) % mid, c = i / (fast * mid);
                    const int x = bx * s.cx + (s.fortran ? c : a), y = by * s.cy + b,
                              z = bz * s.cz + (s.fortran ? a : c);
                    std::uint16_t v = x < s.x && y < s.y && z < s.z ? value(x, y, z) : 0;
                    if (s.big_endian) v = static_cast<std::uint16_t>((v >> 8) | (v << 8));
                    bytes.append(reinterpret_cast<const char*>(&v), 2);
                }
                std::ofstream(dir / key, std::ios::binary) << bytes;
            }
    return dir;
}

TEST(ZarrStream, EveryChunkingStreamsTheVoxelsReadWhole) {
    const auto chunked = [](int cx, int cy, int cz, bool fortran, bool big_endian) {
        ArrayShape s;
        s.cx = cx, s.cy = cy, s.cz = cz, s.fortran = fortran, s.big_endian = big_endian;
        return s;
    };
    ArrayShape left_out;
    left_out.left_out = {"1.0.0", "4.0.2"};
    for (const auto& [name, shape] : std::vector<std::pair<std::string, ArrayShape>>{
             {"rows-of-3", {}},
             {"rows-of-1", chunked(4, 5, 1, false, false)},
             {"rows-of-5-F", chunked(3, 5, 5, true, false)},
             {"one-chunk-big-endian", chunked(11, 9, 13, false, true)},
             {"left-out", left_out}}) {
        SCOPED_TRACE(name);
        const fs::path dir = write_array(name, shape);
        const Volume whole = formats::read_zarr(dir);
        ASSERT_EQ(whole.dims(), glm::ivec3(11, 9, 13));
        const auto at = [&](int x, int y, int z) {
            std::uint16_t v;
            std::memcpy(&v, whole.bytes().data() + 2 * ((std::size_t(z) * 9 + y) * 11 + x), 2);
            return v;
        };
        EXPECT_EQ(at(10, 8, 12), value(10, 8, 12));
        EXPECT_EQ(at(5, 3, 7), value(5, 3, 7));
        if (!shape.left_out.empty()) {
            EXPECT_EQ(at(0, 0, 3), 7) << "a left-out chunk is the fill";
        }
        for (int slab : {1, 2, 3, 6, 20}) {
            SCOPED_TRACE("slab " + std::to_string(slab));
            auto planes = formats::stream_planes(formats::zarr_planes(dir), dir.string());
            test::expect_planes_equal(*planes, whole, slab);
        }
        // And through the child process open_planes decodes in.
        test::expect_streams_alike(dir.string());
    }
}

TEST(ZarrStream, AChunkThatDoesNotDecodeIsNamedWhenItsSlabIsRead) {
    const fs::path dir = write_array("short-chunk", {});
    std::ofstream(dir / "2.1.0", std::ios::binary | std::ios::trunc) << "short";
    auto planes = formats::stream_planes(formats::zarr_planes(dir), dir.string());
    EXPECT_NO_THROW(planes->planes(0, 4));  // rows 0 and 1 (planes 0 to 5) decode
    try {
        planes->planes(4, 8);
        FAIL() << "a damaged chunk streamed";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("2.1.0"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("chunk"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace isowall
