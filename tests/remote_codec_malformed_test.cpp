// The group codecs on hostile bytes: every truncation, seeded random mutations, other versions
// and encodings, trailing bytes, huge counts, bad indices and non-finite floats either decode or
// throw WireError; a huge claimed count throws before anything of its size is allocated.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <new>
#include <random>

#include "remote/group_codec.h"
#include "remote/sample_groups.h"
#include "tests/largest_allocation.h"
#include "volume/phantom.h"

namespace isowall::remote {
namespace {

using test::largest_allocation_in;

using Bytes = std::vector<std::uint8_t>;
constexpr std::size_t kHeaderEnd = 2 + 29;  // version, encoding, group header

// A small real group (a propagation pass of 30 cells), so every truncation is quick to try.
const Group& small_group() {
    static const Group g = [] {
        const Volume p = make_phantom();
        auto groups = sample_groups(p, kPhantomSkinIso, 4, 30);
        return groups.at(0);
    }();
    return g;
}

// Decodes, and when that succeeds checks what a decoded group promises.
void decode_or_wire_error(const Bytes& bytes, const std::string& context) {
    try {
        const Group g = decode_group(bytes);
        const Mesh& m = g.mesh;
        ASSERT_EQ(m.normals.size(), m.positions.size()) << context;
        ASSERT_EQ(m.indices.size() % 3, 0u) << context;
        for (std::uint32_t i : m.indices) ASSERT_LT(i, m.vertex_count()) << context;
        for (const auto& p : m.positions) ASSERT_TRUE(std::isfinite(p.x + p.y + p.z)) << context;
        for (const auto& n : m.normals) ASSERT_TRUE(std::isfinite(n.x + n.y + n.z)) << context;
        ASSERT_TRUE(std::isfinite(g.iso)) << context;
    } catch (const WireError&) {
    }
}

void put_u32(Bytes& b, std::size_t at, std::uint32_t v) {
    std::memcpy(b.data() + at, &v, sizeof v);
}

TEST(RemoteCodecMalformed, EveryTruncationThrows) {
    ASSERT_GT(small_group().mesh.triangle_count(), 10u);
    for (GroupEncoding e : kAllGroupEncodings) {
        const Bytes bytes = encode_group(small_group(), e);
        for (std::size_t n = 0; n < bytes.size(); ++n)
            EXPECT_THROW(decode_group(std::span(bytes).first(n)), WireError)
                << e << " cut to " << n << " of " << bytes.size() << " bytes";
    }
}

TEST(RemoteCodecMalformed, SeededMutationsDecodeOrThrow) {
    std::mt19937 rng(1212);
    for (GroupEncoding e : kAllGroupEncodings) {
        const Bytes clean = encode_group(small_group(), e);
        std::uniform_int_distribution<std::size_t> at(0, clean.size() - 1);
        std::uniform_int_distribution<int> byte(0, 255), flips(1, 4);
        for (int trial = 0; trial < 3000; ++trial) {
            Bytes bytes = clean;
            const int n = flips(rng);
            for (int k = 0; k < n; ++k) bytes[at(rng)] = static_cast<std::uint8_t>(byte(rng));
            decode_or_wire_error(bytes,
                                 std::string(to_string(e)) + " trial " + std::to_string(trial));
        }
    }
}

TEST(RemoteCodecMalformed, AnotherVersionEncodingOrTrailingByteThrows) {
    for (GroupEncoding e : kAllGroupEncodings) {
        Bytes bytes = encode_group(small_group(), e);
        for (int v : {0, kGroupCodecVersion - 1, kGroupCodecVersion + 1, 255}) {
            Bytes b = bytes;
            b[0] = static_cast<std::uint8_t>(v);
            EXPECT_THROW(decode_group(b), WireError) << e << " version " << int(v);
        }
        for (std::uint8_t k : {5, 6, 255}) {
            Bytes b = bytes;
            b[1] = k;
            EXPECT_THROW(decode_group(b), WireError) << e << " encoding " << int(k);
        }
        bytes.push_back(0);
        EXPECT_THROW(decode_group(bytes), WireError) << e << " trailing byte";
    }
}

// The first count after the group header of each encoding (compact+zstd: the u64 size of the
// compact message, right after the encoding byte).
TEST(RemoteCodecMalformed, HugeCountThrowsBeforeAllocating) {
    const std::vector<std::pair<GroupEncoding, std::size_t>> fields{
        {GroupEncoding::vertices, kHeaderEnd},    {GroupEncoding::indexed, kHeaderEnd},
        {GroupEncoding::indexed, kHeaderEnd + 4}, {GroupEncoding::compact, kHeaderEnd},
        {GroupEncoding::compact, kHeaderEnd + 4}, {GroupEncoding::compact_zstd, 2},
        {GroupEncoding::compact_zstd, 6}};
    for (const auto& [e, at] : fields) {
        for (std::uint32_t claim : {0xffffffffu, kMaxGroupVertices, kMaxGroupTriangles, 1u << 20}) {
            Bytes bytes = encode_group(small_group(), e);
            put_u32(bytes, at, claim);
            const std::size_t largest = largest_allocation_in([&] {
                EXPECT_THROW(decode_group(bytes), WireError)
                    << e << " count at " << at << " set to " << claim;
            });
            // Anything decoded is sized from the message itself, never from the claim.
            EXPECT_LT(largest, 16 * bytes.size() + 4096)
                << e << " count at " << at << " set to " << claim;
        }
    }
}

TEST(RemoteCodecMalformed, IndexPastTheVerticesThrows) {
    Bytes bytes = encode_group(small_group(), GroupEncoding::indexed);
    const std::size_t v = small_group().mesh.vertex_count();
    ASSERT_LE(v, kMaxNarrowIndexedVertices);  // so the indices are uint16
    const auto index = static_cast<std::uint16_t>(v);
    std::memcpy(bytes.data() + bytes.size() - 2, &index, sizeof index);
    EXPECT_THROW(decode_group(bytes), WireError);
}

TEST(RemoteCodecMalformed, NonFiniteFloatsThrow) {
    const float bad[] = {std::numeric_limits<float>::quiet_NaN(),
                         std::numeric_limits<float>::infinity()};
    for (float f : bad) {
        for (GroupEncoding e : {GroupEncoding::vertices, GroupEncoding::indexed}) {
            Bytes bytes = encode_group(small_group(), e);
            const std::size_t first_float = kHeaderEnd + (e == GroupEncoding::vertices ? 4 : 8);
            std::memcpy(bytes.data() + first_float + 4, &f, sizeof f);
            EXPECT_THROW(decode_group(bytes), WireError) << e << " " << f;
        }
        Bytes bytes = encode_group(small_group(), GroupEncoding::compact);
        std::memcpy(bytes.data() + kHeaderEnd + 8, &f, sizeof f);  // the box's min.x
        EXPECT_THROW(decode_group(bytes), WireError) << "compact box " << f;
        bytes = encode_group(small_group(), GroupEncoding::indexed);
        const double iso = f;
        std::memcpy(bytes.data() + 2 + 20, &iso, sizeof iso);
        EXPECT_THROW(decode_group(bytes), WireError) << "iso " << f;
    }
}

TEST(RemoteCodecMalformed, InvertedBoxThrows) {
    Bytes bytes = encode_group(small_group(), GroupEncoding::compact);
    const float lo = 1e6f;  // min.x above max.x
    std::memcpy(bytes.data() + kHeaderEnd + 8, &lo, sizeof lo);
    EXPECT_THROW(decode_group(bytes), WireError);
}

// A box whose extent is under about 2e-34 made the encoder's float scale 65535 / extent
// infinite, so a decoded group encoded again had every position on one of the box's ends
// (fuzz_group_codec's first finding). Each axis's sorted corner coordinates stay within a step.
TEST(RemoteCodecMalformed, TinyBoxEncodesAgainWithinAStep) {
    Bytes bytes = encode_group(small_group(), GroupEncoding::compact);
    const float box[6] = {0, 0, 0, 1e-35f, 1e-35f, 1e-35f};
    std::memcpy(bytes.data() + kHeaderEnd + 8, box, sizeof box);
    const Group once = decode_group(bytes);
    const Group twice = decode_group(encode_group(once, GroupEncoding::compact));
    ASSERT_EQ(twice.mesh.triangle_count(), once.mesh.triangle_count());
    for (int a = 0; a < 3; ++a) {
        auto corners = [a](const Mesh& m) {
            std::vector<float> c;
            for (std::uint32_t i : m.indices) c.push_back(m.positions[i][a]);
            std::sort(c.begin(), c.end());
            return c;
        };
        const std::vector<float> c1 = corners(once.mesh), c2 = corners(twice.mesh);
        ASSERT_GT(c1.back(), c1.front()) << "axis " << a << ": the positions spread over the box";
        for (std::size_t i = 0; i < c1.size(); ++i)
            ASSERT_NEAR(c2[i], c1[i], 1e-35 / 65535 + 1e-44) << "axis " << a << " corner " << i;
    }
}

}  // namespace
}  // namespace isowall::remote
