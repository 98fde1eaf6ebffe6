// The group codecs (remote/group_codec.h): real groups of the phantom round-trip through every
// encoding, `vertices` and `indexed` exactly, `compact` within its stated quantisation and normal
// error with every triangle and its winding kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <random>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "remote/compact_mesh.h"
#include "remote/group_codec.h"
#include "remote/sample_groups.h"
#include "volume/phantom.h"

namespace isowall::remote {
namespace {

const std::vector<Group>& phantom_groups() {
    static const std::vector<Group> groups = [] {
        const Volume p = make_phantom();
        return sample_groups(p, kPhantomSkinIso, 24, 2000);
    }();
    return groups;
}

// In doubles and through atan2: acos of a float dot product alone errs by 0.02 degree near 0.
double angle_deg(glm::vec3 a, glm::vec3 b) {
    const glm::dvec3 da(a), db(b);
    return std::atan2(glm::length(glm::cross(da, db)), glm::dot(da, db)) * 180.0 / M_PI;
}

void expect_same_header(const Group& a, const Group& b) {
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.key(), b.key()) << a.key() << " vs " << b.key();
    EXPECT_TRUE(b.cells.empty()) << "cells are not sent";
}

// A triangle as the quantised codes of its corners, rotated so the smallest comes first: the
// same for a triangle and its compact copy (which may start at another corner), different for
// the opposite winding.
using QTriangle = std::array<std::array<std::uint32_t, 3>, 3>;
// The encoder's own formula (remote/compact_mesh.cpp), so an original corner and its decoded
// copy get the same code.
struct Quantiser {
    glm::vec3 lo, step;
    glm::dvec3 scale{0};
    explicit Quantiser(const Box3& box) : lo(box.min), step((box.max - box.min) / 65535.0f) {
        for (int a = 0; a < 3; ++a)
            if (box.max[a] > box.min[a]) scale[a] = 65535.0 / double{box.max[a] - box.min[a]};
    }
    std::array<std::uint32_t, 3> operator()(glm::vec3 p) const {
        std::array<std::uint32_t, 3> q{};
        const glm::dvec3 s = glm::dvec3(p - lo) * scale;
        for (int a = 0; a < 3; ++a)
            q[a] = static_cast<std::uint32_t>(std::lround(std::clamp(s[a], 0.0, 65535.0)));
        return q;
    }
};
// The smallest of the three rotations: a degenerate triangle has two equal corners, so "start
// at the smallest corner" alone would not be one rotation.
QTriangle canonical(const Mesh& m, std::size_t t, const Quantiser& q) {
    QTriangle c;
    for (int k = 0; k < 3; ++k) c[k] = q(m.positions[m.indices[3 * t + k]]);
    QTriangle best = c;
    for (int r = 1; r < 3; ++r) {
        std::rotate(c.begin(), c.begin() + 1, c.end());
        best = std::min(best, c);
    }
    return best;
}

TEST(RemoteCodec, EmptyGroupRoundTripsInEveryEncoding) {
    Group g;
    g.id = 7;
    g.seed = {1, -2, 3};
    g.level = 2;
    g.iso = -0.5;
    g.refinement = true;
    for (GroupEncoding e : kAllGroupEncodings) {
        const auto bytes = encode_group(g, e);
        // cells needs the volume and at least one unit: the group goes as compact+zstd.
        EXPECT_EQ(encoding_of(bytes), e == GroupEncoding::cells ? GroupEncoding::compact_zstd : e);
        const Group back = decode_group(bytes);
        expect_same_header(g, back);
        EXPECT_TRUE(back.mesh.empty()) << e;
        EXPECT_EQ(back.mesh.vertex_count(), 0u) << e;
    }
}

TEST(RemoteCodec, IndexedIsExact) {
    ASSERT_GT(phantom_groups().size(), 10u);
    for (const Group& g : phantom_groups()) {
        const Group back = decode_group(encode_group(g, GroupEncoding::indexed));
        expect_same_header(g, back);
        EXPECT_EQ(back.mesh.positions, g.mesh.positions) << "group " << g.id;
        EXPECT_EQ(back.mesh.normals, g.mesh.normals) << "group " << g.id;
        EXPECT_EQ(back.mesh.indices, g.mesh.indices) << "group " << g.id;
    }
}

TEST(RemoteCodec, VerticesAreExactCornerByCorner) {
    for (const Group& g : phantom_groups()) {
        const auto bytes = encode_group(g, GroupEncoding::vertices);
        EXPECT_EQ(bytes.size(), 2 + 29 + 4 + 72 * g.mesh.triangle_count());
        const Group back = decode_group(bytes);
        expect_same_header(g, back);
        ASSERT_EQ(back.mesh.indices.size(), g.mesh.indices.size());
        for (std::size_t i = 0; i < g.mesh.indices.size(); ++i) {
            ASSERT_EQ(back.mesh.positions[back.mesh.indices[i]],
                      g.mesh.positions[g.mesh.indices[i]])
                << "group " << g.id << " corner " << i;
            ASSERT_EQ(back.mesh.normals[back.mesh.indices[i]], g.mesh.normals[g.mesh.indices[i]])
                << "group " << g.id << " corner " << i;
        }
    }
}

// The errors of decoded triangle t of b against original triangle o of m: position in box
// steps and normal in degrees, corner by corner over the rotations whose codes match (a
// degenerate triangle may match more than one); the best rotation counts.
std::pair<double, double> triangle_error(const Mesh& b, std::size_t t, const Mesh& m, std::size_t o,
                                         const Quantiser& q) {
    std::pair<double, double> best{1e300, 1e300};
    for (int shift = 0; shift < 3; ++shift) {
        double steps = 0, deg = 0;
        bool same = true;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t bi = b.indices[3 * t + k], oi = m.indices[3 * o + (k + shift) % 3];
            same = same && q(b.positions[bi]) == q(m.positions[oi]);
            for (int a = 0; a < 3; ++a)
                if (q.step[a] > 0)
                    steps = std::max(
                        steps,
                        double(std::abs(b.positions[bi][a] - m.positions[oi][a]) / q.step[a]));
            deg = std::max(deg, angle_deg(b.normals[bi], m.normals[oi]));
        }
        if (same && deg < best.second) best = {steps, deg};
    }
    return best;
}

// Checks one compact round trip: every decoded triangle is an original one with the same
// winding, none lost. Returns the largest position error in box steps (extent / 65535) and the
// largest normal error in degrees.
std::pair<double, double> check_compact(const Group& g, GroupEncoding e) {
    const Group back = decode_group(encode_group(g, e));
    expect_same_header(g, back);
    const Mesh& m = g.mesh;
    const Mesh& b = back.mesh;
    EXPECT_EQ(b.triangle_count(), m.triangle_count()) << "group " << g.id;
    const Quantiser q(m.bounds());
    std::multimap<QTriangle, std::size_t> originals;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) originals.emplace(canonical(m, t, q), t);
    double worst_steps = 0, worst_deg = 0;
    for (std::size_t t = 0; t < b.triangle_count(); ++t) {
        auto [first, last] = originals.equal_range(canonical(b, t, q));
        if (first == last) {
            ADD_FAILURE() << "group " << g.id << ": decoded triangle " << t
                          << " matches no original one with the same winding";
            continue;
        }
        // Equal codes may be several degenerate triangles: the closest one is this one.
        auto match = first;
        std::pair<double, double> err{1e300, 1e300};
        for (auto it = first; it != last; ++it) {
            const auto e2 = triangle_error(b, t, m, it->second, q);
            if (e2.second < err.second) err = e2, match = it;
        }
        worst_steps = std::max(worst_steps, err.first);
        worst_deg = std::max(worst_deg, err.second);
        originals.erase(match);
    }
    EXPECT_TRUE(originals.empty()) << "group " << g.id << ": " << originals.size() << " lost";
    return {worst_steps, worst_deg};
}

TEST(RemoteCodec, CompactKeepsTrianglesAndWindingWithinTheQuantisation) {
    for (GroupEncoding e : {GroupEncoding::compact, GroupEncoding::compact_zstd}) {
        double steps = 0, deg = 0;
        for (const Group& g : phantom_groups()) {
            const auto [s, d] = check_compact(g, e);
            steps = std::max(steps, s);
            deg = std::max(deg, d);
        }
        std::cout << e << ": largest position error " << steps
                  << " box steps (extent / 65535), largest normal error " << deg << " degree\n";
        EXPECT_LE(steps, 1.0) << e;
        EXPECT_LE(deg, kOctNormalMaxErrorDeg) << e;
    }
}

TEST(RemoteCodec, OctahedralNormalsErrUnderTheStatedAngle) {
    std::mt19937 rng(12);
    std::normal_distribution<float> gauss;
    std::vector<glm::vec3> dirs{{1, 0, 0},
                                {-1, 0, 0},
                                {0, 1, 0},
                                {0, -1, 0},
                                {0, 0, 1},
                                {0, 0, -1},
                                glm::normalize(glm::vec3(1, 1, 1)),
                                glm::normalize(glm::vec3(-1, 1, -1))};
    for (int i = 0; i < 1000000; ++i) {
        const glm::vec3 v(gauss(rng), gauss(rng), gauss(rng));
        if (glm::length(v) > 1e-6f) dirs.push_back(glm::normalize(v));
    }
    double worst = 0;
    for (const glm::vec3& n : dirs) {
        const glm::vec3 d = oct_decode(oct_encode(n));
        ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
        worst = std::max(worst, angle_deg(n, d));
    }
    std::cout << "octahedral 2 x 16 bits: largest error " << worst << " degree over " << dirs.size()
              << " directions\n";
    EXPECT_LE(worst, kOctNormalMaxErrorDeg);
    // Every code decodes to a unit vector, the extremes included.
    for (std::int16_t a : {-32768, -32767, 0, 32767})
        for (std::int16_t b : {-32768, -1, 0, 1, 32767})
            EXPECT_NEAR(glm::length(oct_decode({a, b})), 1.0f, 1e-5f) << a << " " << b;
}

TEST(RemoteCodec, EachStepIsSmallerOnAFrame) {
    static const Volume phantom = make_phantom();
    std::map<GroupEncoding, std::size_t> total;
    for (const Group& g : phantom_groups())
        for (GroupEncoding e : kAllGroupEncodings)
            total[e] += encode_group(g, e, 0, &phantom).size();
    for (GroupEncoding e : kAllGroupEncodings) std::cout << e << ": " << total[e] << " bytes\n";
    EXPECT_LT(total[GroupEncoding::indexed], total[GroupEncoding::vertices]);
    EXPECT_LT(total[GroupEncoding::compact], total[GroupEncoding::indexed] / 2);
    EXPECT_LT(total[GroupEncoding::compact_zstd], total[GroupEncoding::compact]);
    // cells: at most a quarter of compact+zstd on the phantom's frame.
    EXPECT_LT(total[GroupEncoding::cells], total[GroupEncoding::compact_zstd] / 4);
}

// Indices go as uint16 up to 65536 vertices (index 65535 included) and as uint32 beyond.
TEST(RemoteCodec, IndexedSendsTwoByteIndicesUpTo65536Vertices) {
    std::map<std::size_t, std::size_t> sizes;
    for (std::size_t n : {std::size_t{65536}, std::size_t{65537}}) {
        Group g;
        g.iso = 3;
        for (std::size_t i = 0; i < n; ++i) {
            g.mesh.positions.emplace_back(float(i % 256), float(i / 256), 0.5f);
            g.mesh.normals.emplace_back(0, 0, 1);
        }
        const auto last = static_cast<std::uint32_t>(n - 1);
        g.mesh.indices = {0, 1, last, last, 1, 2, 256, last, 0};
        const auto bytes = encode_group(g, GroupEncoding::indexed);
        sizes[n] = bytes.size();
        const Group back = decode_group(bytes);
        EXPECT_EQ(back.mesh.indices, g.mesh.indices) << n << " vertices";
        EXPECT_EQ(back.mesh.positions, g.mesh.positions) << n << " vertices";
    }
    // One more vertex (24 bytes) and nine indices of 4 bytes instead of 2.
    EXPECT_EQ(sizes[65537] - sizes[65536], 24u + 9u * 2u);
}

TEST(RemoteCodec, WholeSurfaceRoundTripsAsOneGroup) {
    const Volume p = make_phantom();
    Group g;
    g.iso = kPhantomBoneIso;
    g.mesh = make_surface_extractor(p)->extract_full(kPhantomBoneIso);
    ASSERT_GT(g.mesh.triangle_count(), 10000u);
    const Group back = decode_group(encode_group(g, GroupEncoding::indexed));
    EXPECT_EQ(back.mesh.indices, g.mesh.indices);
    const auto [steps, deg] = check_compact(g, GroupEncoding::compact_zstd);
    EXPECT_LE(steps, 1.0);
    EXPECT_LE(deg, kOctNormalMaxErrorDeg);
}

TEST(RemoteCodec, EncodingRefusesAMalformedMesh) {
    Group g;
    g.mesh.positions = {glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)};
    g.mesh.normals = {glm::vec3(0, 0, 1), glm::vec3(0, 0, 1), glm::vec3(0, 0, 1)};
    g.mesh.indices = {0, 1, 3};
    EXPECT_THROW(encode_group(g, GroupEncoding::compact), std::invalid_argument);
    g.mesh.indices = {0, 1};
    EXPECT_THROW(encode_group(g, GroupEncoding::indexed), std::invalid_argument);
}

}  // namespace
}  // namespace isowall::remote
