// The `cells` encoding (remote/cell_codec.h): a group sent as its units and the voxel values
// marching cubes reads, triangulated again by the client. Round trips give the server's triangles
// (same corners, same winding, positions to float rounding) and the very same normals at full
// resolution and for refinements; a coarse pass's come with its vertices near the server's (its
// values travel to a step) and normals from its faces: on the phantom, at meta-cell levels (with
// cells at the volume's border), and on every shared volume at its README isovalues; the step's
// bins keep every value's side of the isovalue. Hostile bodies (every
// truncation, seeded mutations, huge counts, units past the volume) throw WireError, and a huge
// claim throws before anything of its size is allocated.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <unordered_map>

#include "remote/cell_codec.h"
#include "remote/group_codec.h"
#include "remote/sample_groups.h"
#include "tests/largest_allocation.h"
#include "tests/test_util.h"
#include "volume/phantom.h"

namespace isowall::remote {
namespace {

using Bytes = std::vector<std::uint8_t>;

const Volume& cells_phantom() {
    static const Volume v = make_phantom();
    return v;
}

// A triangle as its corners' positions and normals, turned so the smallest corner comes first
// (winding kept).
using Corner = std::array<float, 6>;
using Triangle = std::array<Corner, 3>;

// with_normals false: the normals left out (0).
std::vector<Triangle> triangles_of(const Mesh& m, bool with_normals = true) {
    std::vector<Triangle> out;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        Triangle tri;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t i = m.indices[t + static_cast<std::size_t>(k)];
            const glm::vec3 p = m.positions[i], n = with_normals ? m.normals[i] : glm::vec3(0);
            tri[static_cast<std::size_t>(k)] = {p.x, p.y, p.z, n.x, n.y, n.z};
        }
        const auto first = std::min_element(tri.begin(), tri.end()) - tri.begin();
        std::rotate(tri.begin(), tri.begin() + first, tri.end());
        out.push_back(tri);
    }
    std::sort(out.begin(), out.end());
    return out;
}

// In doubles and through atan2: acos of a float dot product alone errs near 0.
double normal_angle_deg(glm::vec3 a, glm::vec3 b) {
    const glm::dvec3 da(a), db(b);
    return std::atan2(glm::length(glm::cross(da, db)), glm::dot(da, db)) * 180.0 / M_PI;
}

// `got` has the triangles of `want`, corner by corner, with the same winding, positions and
// normals to the bit: the client runs the server's arithmetic on the server's voxel values.
void expect_same_mesh(const Mesh& got, const Mesh& want, const std::string& what) {
    ASSERT_EQ(got.triangle_count(), want.triangle_count()) << what;
    const std::vector<Triangle> a = triangles_of(got), b = triangles_of(want);
    std::vector<Triangle> only_a;
    std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(only_a));
    EXPECT_TRUE(only_a.empty()) << what << ": " << only_a.size() << " of " << a.size()
                                << " triangles differ from the server's";
}

// A coarse pass (cell_codec.h): its values travel to a step, so its vertices move along their
// edges, and its normals come from its faces. `got` has `want`'s triangle count (the same units
// and cases: the step keeps every value's side of the isovalue), each vertex near one of
// `want`'s (`edge`: the pass's edge length), normals that are its own faces' and that face the
// side the server's gradients do.
void expect_close_mesh(const Mesh& got, const Mesh& want, const std::string& what, float edge) {
    ASSERT_EQ(got.triangle_count(), want.triangle_count()) << what;
    Mesh faces = got;
    normals_from_faces(faces);
    EXPECT_TRUE(faces.normals == got.normals) << what << ": normals not from the faces";
    std::map<std::array<int, 3>, std::vector<std::size_t>> near;
    auto cell = [&](glm::vec3 p) {
        const glm::ivec3 c(glm::floor(p / edge));
        return std::array<int, 3>{c.x, c.y, c.z};
    };
    for (std::size_t i = 0; i < want.vertex_count(); ++i)
        near[cell(want.positions[i])].push_back(i);
    double moved = 0, farthest = 0, angle = 0;
    for (std::size_t i = 0; i < got.vertex_count(); ++i) {
        const glm::vec3 p = got.positions[i];
        const auto c = cell(p);
        double best = 1e30;
        std::size_t at = 0;
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const auto it = near.find({c[0] + dx, c[1] + dy, c[2] + dz});
                    if (it == near.end()) continue;
                    for (const std::size_t k : it->second) {
                        const double d = glm::length(glm::dvec3(p - want.positions[k]));
                        if (d < best) best = d, at = k;
                    }
                }
        ASSERT_LT(best, 1e30) << what << ": a vertex with none of the server's within an edge";
        moved += best;
        farthest = std::max(farthest, best);
        angle += normal_angle_deg(got.normals[i], want.normals[at]);
    }
    if (got.vertex_count() == 0) return;
    const double n = double(got.vertex_count());
    std::printf("%s: vertices moved %.3f edges on average, %.3f at most; normals %.1f degrees\n",
                what.c_str(), moved / n / edge, farthest / edge, angle / n);
    EXPECT_LT(moved / n, 0.06 * edge) << what << ": mean distance to the server's vertices";
    EXPECT_LT(farthest, 1.0 * edge) << what << ": a vertex moved past its edge";
    // 28 degrees apart on average on the head's coarse passes, up to 50 on cthead's small ones
    // (noisy 16-bit gradients at the crossings); normals turned inside out would be over 90.
    EXPECT_LT(angle / n, 75.0) << what << ": mean normal angle";
}

// The group through its cells body; and encode_group's choice: cells at full resolution, and for
// a coarse pass the smaller of cells and compact+zstd.
Group round_trip(const Group& g, const Volume& v) {
    const Bytes bytes = encode_group(g, GroupEncoding::cells, 0, &v);
    const auto body = encode_cell_body(g, v);
    EXPECT_TRUE(body.has_value()) << g.key();
    if (!body) return {};
    if (g.level == 0 || g.refinement) {
        EXPECT_EQ(encoding_of(bytes), GroupEncoding::cells) << g.key();
    } else {
        EXPECT_LE(bytes.size(), encode_group(g, GroupEncoding::compact_zstd).size())
            << g.key() << ": a coarse pass goes in the smaller";
    }
    Group back = decode_group(bytes);
    ByteReader r(*body, "cells");
    back.mesh = decode_cell_body(r, g.iso);
    r.finish();
    return back;
}

void expect_round_trips(const std::vector<Group>& groups, const Volume& v,
                        const std::string& what) {
    ASSERT_FALSE(groups.empty()) << what;
    for (const Group& g : groups) {
        const Group back = round_trip(g, v);
        EXPECT_EQ(back.key(), g.key());
        const std::string name = what + " group " + std::to_string(g.id);
        if (g.level >= 1 && !g.refinement) {
            const glm::vec3 s = v.spacing();
            const float edge = float(1 << g.level) * std::max({s.x, s.y, s.z});
            expect_close_mesh(back.mesh, g.mesh, name, edge);
        } else {
            expect_same_mesh(back.mesh, g.mesh, name);
        }
        if (testing::Test::HasFailure()) return;
    }
}

TEST(RemoteCellCodec, CellsGiveTheServersTrianglesAndNormals) {
    expect_round_trips(sample_groups(cells_phantom(), kPhantomSkinIso, 24, 2000), cells_phantom(),
                       "level 0");
}

TEST(RemoteCellCodec, MetaCellsAndTheCellsAtTheBorderRoundTrip) {
    for (int level : {1, 2, 3}) {
        const auto groups =
            sample_groups(cells_phantom(), kPhantomSkinIso, 24, 2000, uniform_levels(level));
        bool mixed = false;
        for (const Group& g : groups) mixed = mixed || !g.cell_levels.empty();
        std::printf("level %d: %zu groups, %s\n", level, groups.size(),
                    mixed ? "some with cells at the border" : "one level each");
        expect_round_trips(groups, cells_phantom(), "level " + std::to_string(level));
    }
}

TEST(RemoteCellCodec, RefinementsRoundTrip) {
    auto ex = make_surface_extractor(cells_phantom());
    ex->begin_frame(kPhantomSkinIso, uniform_levels(3));
    const auto coarse = sample_groups(cells_phantom(), kPhantomSkinIso, 6, 200, uniform_levels(3));
    PropagationParams params;
    int refined = 0;
    for (const Group& g : coarse)
        for (std::size_t i = 0; i < g.cells.size() && refined < 40; i += 7) {
            if (g.level_of_cell(i) != 3) continue;
            const Group r = ex->refine(g.cells[i], 3, static_cast<std::uint32_t>(refined), params);
            if (r.mesh.empty()) continue;
            ++refined;
            ASSERT_TRUE(r.refinement);
            expect_same_mesh(round_trip(r, cells_phantom()).mesh, r.mesh,
                             "refinement " + std::to_string(refined));
        }
    EXPECT_GE(refined, 10);
}

// Every shared volume's groups at its README isovalues: 16-bit and 8-bit voxels, anisotropic
// spacing, a heavy noisy surface and a fragmented one.
TEST(RemoteCellCodec, EverySharedVolumeRoundTrips) {
    const auto data = test::shared_data_dir();
    if (!data) GTEST_SKIP() << "../shared/data is absent: the shared volumes are not checked";
    for (const auto& [name, iso] : test::shared_isovalues()) {
        const Volume v = load_volume(*data / (name + ".nhdr"), std::nullopt);
        std::size_t bytes_cells = 0, bytes_compact = 0, triangles = 0;
        for (int level : {0, 2}) {
            const auto groups = sample_groups(v, iso, 16, 2000, uniform_levels(level));
            expect_round_trips(groups, v, name + " " + std::to_string(iso));
            if (testing::Test::HasFailure()) return;
            if (level != 0) continue;
            for (const Group& g : groups) {
                bytes_cells += encode_group(g, GroupEncoding::cells, 0, &v).size();
                bytes_compact += encode_group(g, GroupEncoding::compact_zstd).size();
                triangles += g.mesh.triangle_count();
            }
        }
        std::printf("%s at %g: %zu triangles, cells %.2f B/triangle, compact+zstd %.2f\n",
                    name.c_str(), iso, triangles, double(bytes_cells) / double(triangles),
                    double(bytes_compact) / double(triangles));
    }
}

TEST(RemoteCellCodec, AGroupWhoseMeshIsNotItsUnitsGoesAsCompact) {
    Group g = sample_groups(cells_phantom(), kPhantomSkinIso, 4, 30).at(0);
    g.mesh.indices.resize(g.mesh.indices.size() - 3);  // one triangle fewer than its cells make
    EXPECT_EQ(encoding_of(encode_group(g, GroupEncoding::cells, 0, &cells_phantom())),
              GroupEncoding::compact_zstd);
    EXPECT_EQ(encoding_of(encode_group(g, GroupEncoding::cells)), GroupEncoding::compact_zstd)
        << "no volume";
}

// ---- hostile bodies --------------------------------------------------------------------------

const Group& cells_group() {
    static const Group g = sample_groups(cells_phantom(), kPhantomSkinIso, 4, 30).at(0);
    return g;
}

Bytes cells_body() {
    return encode_cell_body(cells_group(), cells_phantom()).value();
}

Mesh decode_body(const Bytes& b) {
    ByteReader r(b, "cells");
    Mesh m = decode_cell_body(r, cells_group().iso);
    r.finish();
    return m;
}

TEST(RemoteCellCodecMalformed, EveryTruncationThrows) {
    const Bytes body = cells_body();
    expect_same_mesh(decode_body(body), cells_group().mesh, "the clean body");
    for (std::size_t n = 0; n < body.size(); ++n)
        EXPECT_THROW(decode_body(Bytes(body.begin(), body.begin() + long(n))), WireError)
            << "cut to " << n << " of " << body.size();
    Bytes longer = body;
    longer.push_back(0);
    EXPECT_THROW(decode_body(longer), WireError) << "a trailing byte";
}

TEST(RemoteCellCodecMalformed, SeededMutationsDecodeOrThrow) {
    const Bytes clean = cells_body();
    std::mt19937 rng(3434);
    std::uniform_int_distribution<std::size_t> at(0, clean.size() - 1);
    std::uniform_int_distribution<int> byte(0, 255), flips(1, 4);
    int decoded = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        Bytes b = clean;
        for (int k = flips(rng); k > 0; --k) b[at(rng)] = static_cast<std::uint8_t>(byte(rng));
        try {
            const Mesh m = decode_body(b);
            ++decoded;
            ASSERT_EQ(m.normals.size(), m.positions.size());
            for (std::uint32_t i : m.indices) ASSERT_LT(i, m.vertex_count());
            for (const auto& p : m.positions) ASSERT_TRUE(std::isfinite(p.x + p.y + p.z));
            for (const auto& n : m.normals) ASSERT_TRUE(std::isfinite(n.x + n.y + n.z));
        } catch (const WireError&) {
        }
    }
    std::printf("%d of 4000 mutated bodies decoded (the rest threw WireError)\n", decoded);
}

void overwrite_u32(Bytes& b, std::size_t at, std::uint32_t v) {
    std::memcpy(b.data() + at, &v, sizeof v);
}

void put_leb128(Bytes& b, std::uint32_t v) {
    for (; v >= 0x80; v >>= 7) b.push_back(static_cast<std::uint8_t>(v | 0x80));
    b.push_back(static_cast<std::uint8_t>(v));
}

// Two units in a box of `size` units at the origin of a volume of `dims`, and `stream` bytes of
// coded stream.
Bytes spread_units_body(const Bytes& clean, glm::uvec3 dims, glm::uvec3 size,
                        std::uint32_t stream) {
    Bytes b(clean.begin(), clean.begin() + 26);  // to the normals byte (gradients)
    for (int a = 0; a < 3; ++a) overwrite_u32(b, 1 + 4 * std::size_t(a), dims[a]);
    b.push_back(1);  // one bucket
    b.push_back(0);  // level 0
    const std::uint32_t two = 2;
    b.insert(b.end(), reinterpret_cast<const std::uint8_t*>(&two),
             reinterpret_cast<const std::uint8_t*>(&two) + 4);
    for (int a = 0; a < 3; ++a) b.push_back(0);  // the box's origin
    for (int a = 0; a < 3; ++a) put_leb128(b, size[a]);
    b.push_back(0);  // the values exact
    b.insert(b.end(), reinterpret_cast<const std::uint8_t*>(&stream),
             reinterpret_cast<const std::uint8_t*>(&stream) + 4);
    b.insert(b.end(), stream, 7);
    return b;
}

// Offsets in the body: type u8 at 0, dims at 1, spacing at 13, normals at 25, bucket count at 26,
// the first bucket's level at 27 and unit count at 28, its box's origin at 32.
TEST(RemoteCellCodecMalformed, HugeCountsAndUnitsPastTheVolumeThrowBeforeAllocating) {
    const Bytes clean = cells_body();
    // Throws WireError whose message holds `why`.
    auto expect_refused = [&](const Bytes& b, const std::string& what, const std::string& why) {
        std::string message;
        const std::size_t largest = test::largest_allocation_in([&] {
            try {
                decode_body(b);
            } catch (const WireError& e) {
                message = e.what();
            }
        });
        EXPECT_NE(message.find(why), std::string::npos)
            << what << ": expected a WireError saying \"" << why << "\", got \"" << message << "\"";
        // The box's brick directory (at most kMaxCellBoxVoxels / 64 entries) is the one thing
        // sized before the values are read; nothing is sized from a count past the bytes.
        EXPECT_LT(largest, std::size_t{1} << 21) << what;
    };
    for (std::uint32_t claim : {0xffffffffu, kMaxGroupTriangles, 1u << 20, 5000u}) {
        Bytes b = clean;
        overwrite_u32(b, 28, claim);
        expect_refused(b, "unit count " + std::to_string(claim),
                       claim > kMaxGroupTriangles ? "over the limit" : "places of its box");
    }
    for (std::uint32_t dim : {0u, 1u, 0x7fffffffu, 0x80000000u}) {
        Bytes b = clean;
        overwrite_u32(b, 1, dim);
        expect_refused(b, "dims.x " + std::to_string(dim), "volume dims");
    }
    {
        Bytes b = clean;
        b[0] = 200;
        expect_refused(b, "voxel type 200", "voxel type");
    }
    {
        Bytes b = clean;
        ASSERT_EQ(b[25], 0) << "a full-resolution pass's normals come from its voxels";
        b[25] = 2;
        expect_refused(b, "normals 2", "normals");
    }
    {
        Bytes b = clean;
        b[27] = 40;
        expect_refused(b, "level 40", "unit level 40");
    }
    {
        // A box origin past every unit of the volume: ten LEB128 bytes of 0xff, then 0x01.
        Bytes b(clean.begin(), clean.begin() + 32);
        for (int k = 0; k < 9; ++k) b.push_back(0xff);
        b.push_back(0x01);
        b.insert(b.end(), clean.begin() + 33, clean.end());
        expect_refused(b, "a unit past the volume", "past the volume");
    }
    const glm::uvec3 big(4096);
    expect_refused(spread_units_body(clean, big, glm::uvec3(4095), 64),
                   "units spread past the box limit", "spread over");
    // 8 million places, which 64 bytes of stream cannot code (at most 364 a byte).
    expect_refused(spread_units_body(clean, big, glm::uvec3(200), 64),
                   "a box past what the stream can code", "more than the coded stream can hold");
    // 3.8 million places a 10 KB stream could code, but a thin box: with the border the coder
    // reads around it, 17 million.
    expect_refused(spread_units_body(clean, {4096, 4096, 300000}, {1, 16, 240000}, 10240),
                   "a thin box whose border is past the limit", "with their borders");
}

}  // namespace
}  // namespace isowall::remote
