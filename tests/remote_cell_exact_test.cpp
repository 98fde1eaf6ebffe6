// A cells group in two messages (remote/cell_codec.h, cell_exact.h): its gradients' voxels to a
// step first, their exact offsets after. The stepped body gives the server's vertices to the bit
// (only normals move); with the offsets, the very mesh the exact body gives. On the phantom and on
// every shared volume at its README isovalues. Hostile offsets (a byte short or over, bits past
// the last value, offsets for a body that is exact, for a compact group, every truncation) throw
// WireError.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "remote/cell_codec.h"
#include "remote/cell_exact.h"
#include "remote/group_codec.h"
#include "remote/sample_groups.h"
#include "tests/test_util.h"
#include "volume/phantom.h"

namespace isowall::remote {
namespace {

using Bytes = std::vector<std::uint8_t>;

Mesh decode_two(const Bytes& group, const Bytes* exact, bool* stepped = nullptr) {
    const std::span<const std::uint8_t> bits =
        exact ? std::span(*exact) : std::span<const std::uint8_t>();
    return decode_group(group, {exact ? &bits : nullptr, stepped}).mesh;
}

double exact_angle_deg(glm::vec3 a, glm::vec3 b) {
    const float c = std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.f, 1.f);
    return std::acos(double(c)) * 180.0 / 3.14159265358979;
}

struct ExactTally {
    std::size_t groups = 0, stepped = 0, bytes_exact = 0, bytes_first = 0, bytes_after = 0;
    double angle_sum = 0, angle_max = 0;
    std::size_t vertices = 0;
};

// Every group of `groups` both ways; returns what it saw.
ExactTally exact_check_groups(const std::vector<Group>& groups, const Volume& v,
                              const std::string& what) {
    ExactTally t;
    for (const Group& g : groups) {
        const Bytes whole = encode_group(g, GroupEncoding::cells, 0, &v);
        Bytes exact;
        const Bytes first = encode_group(g, GroupEncoding::cells, 0, &v, &exact);
        ++t.groups;
        t.bytes_exact += whole.size();
        t.bytes_first += first.size();
        t.bytes_after += exact.size();
        bool stepped = true;
        const Mesh want = decode_two(whole, nullptr, &stepped);
        EXPECT_FALSE(stepped) << what << ": a body encoded without offsets is exact";
        const Mesh rough = decode_two(first, nullptr, &stepped);
        EXPECT_EQ(stepped, !exact.empty()) << what << " " << g.key();
        if (exact.empty()) {
            EXPECT_EQ(first, whole) << what << ": nothing stepped, the same bytes";
            continue;
        }
        ++t.stepped;
        // The vertices are where the server put them; only the normals moved.
        EXPECT_EQ(rough.positions, want.positions) << what << " " << g.key();
        EXPECT_EQ(rough.indices, want.indices) << what << " " << g.key();
        for (std::size_t i = 0; i < rough.normals.size() && i < want.normals.size(); ++i) {
            const double a = exact_angle_deg(rough.normals[i], want.normals[i]);
            t.angle_sum += a;
            t.angle_max = std::max(t.angle_max, a);
        }
        t.vertices += rough.normals.size();
        const Mesh back = decode_two(first, &exact);
        EXPECT_EQ(back.positions, want.positions) << what << " " << g.key();
        EXPECT_EQ(back.normals, want.normals) << what << " " << g.key() << ": exact normals";
        EXPECT_EQ(back.indices, want.indices) << what << " " << g.key();
        if (testing::Test::HasFailure()) break;
    }
    std::printf(
        "%s: %zu groups, %zu stepped; bytes %zu exact, %zu + %zu in two (%.3f first); "
        "normals %.2f degrees apart on average, %.1f at most\n",
        what.c_str(), t.groups, t.stepped, t.bytes_exact, t.bytes_first, t.bytes_after,
        double(t.bytes_first) / double(t.bytes_exact),
        t.vertices ? t.angle_sum / double(t.vertices) : 0.0, t.angle_max);
    return t;
}

TEST(RemoteCellExact, ThePhantomsGroupsComeExactFromBothMessages) {
    const Volume v = make_phantom();
    const ExactTally t =
        exact_check_groups(sample_groups(v, kPhantomSkinIso, 24, 2000), v, "phantom");
    EXPECT_GT(t.groups, 0u);
}

TEST(RemoteCellExact, ACoarsePassIsNeverSteppedForOffsets) {
    const Volume v = make_phantom();
    for (const Group& g : sample_groups(v, kPhantomSkinIso, 24, 2000, uniform_levels(2))) {
        Bytes exact{1, 2, 3};
        const Bytes bytes = encode_group(g, GroupEncoding::cells, 0, &v, &exact);
        EXPECT_TRUE(exact.empty()) << g.key() << ": its values go to a step of their own";
        if (encoding_of(bytes) != GroupEncoding::cells) continue;
        bool stepped = true;
        decode_two(bytes, nullptr, &stepped);
        EXPECT_FALSE(stepped) << g.key() << ": nothing undoes a coarse pass's step";
        EXPECT_THROW(decode_two(bytes, &exact), WireError) << g.key();
    }
}

TEST(RemoteCellExact, EverySharedVolumeComesExactFromBothMessages) {
    const auto data = test::shared_data_dir();
    if (!data) GTEST_SKIP() << "../shared/data is absent: the shared volumes are not checked";
    for (const auto& [name, iso] : test::shared_isovalues()) {
        const Volume v = load_volume(*data / (name + ".nhdr"), std::nullopt);
        const ExactTally t = exact_check_groups(sample_groups(v, iso, 16, 2000), v,
                                                name + " at " + std::to_string(int(iso)));
        if (testing::Test::HasFailure()) return;
        if (v.type() == VoxelType::u16) {
            EXPECT_GT(t.stepped, t.groups / 2) << name << ": 16-bit gradients go to a step";
            EXPECT_LT(t.bytes_first, t.bytes_exact) << name << ": the first message is smaller";
        }
    }
}

// ---- hostile offsets ---------------------------------------------------------------------------

struct SteppedBytes {
    Bytes group, exact;
};

// A cthead group whose gradients went to a step (the phantom's may not: its edges span few
// values), or nothing without the shared data.
const SteppedBytes* exact_stepped_group() {
    static const std::optional<SteppedBytes> s = []() -> std::optional<SteppedBytes> {
        const auto data = test::shared_data_dir();
        if (!data) return std::nullopt;
        const Volume v = load_volume(*data / "cthead.nhdr", std::nullopt);
        for (const Group& g : sample_groups(v, 600, 8, 300)) {
            SteppedBytes s;
            s.group = encode_group(g, GroupEncoding::cells, 0, &v, &s.exact);
            if (!s.exact.empty()) return s;
        }
        return std::nullopt;
    }();
    return s ? &*s : nullptr;
}

void exact_expect_wire_error(const Bytes& group, const Bytes& exact, const std::string& what) {
    EXPECT_THROW(decode_two(group, &exact), WireError) << what;
}

TEST(RemoteCellExactMalformed, OffsetsOfTheWrongLengthOrWithStrayBitsThrow) {
    const SteppedBytes* s = exact_stepped_group();
    if (!s) GTEST_SKIP() << "../shared/data is absent: no 16-bit group to step";
    ASSERT_NO_THROW(decode_two(s->group, &s->exact));
    for (std::size_t n = 0; n < s->exact.size(); ++n)
        exact_expect_wire_error(s->group, Bytes(s->exact.begin(), s->exact.begin() + long(n)),
                                "cut to " + std::to_string(n) + " bytes");
    Bytes longer = s->exact;
    longer.push_back(0);
    exact_expect_wire_error(s->group, longer, "a byte over");
    // Three values of 3 bits fill 9 bits of 2 bytes: the second byte's bits 1-7 are unused.
    const Bytes nine{0xff, 0x01};
    EXPECT_EQ(cells::exact_bits_problem(nine, 3, 3), "");
    for (int bit = 1; bit < 8; ++bit)
        EXPECT_EQ(cells::exact_bits_problem(Bytes{0xff, std::uint8_t(1u | 1u << bit)}, 3, 3),
                  "the exact values' unused bits are not zero")
            << "unused bit " << bit;
}

TEST(RemoteCellExactMalformed, OffsetsForAnExactBodyOrACompactGroupThrow) {
    const Volume v = make_phantom();
    const Group g = sample_groups(v, kPhantomSkinIso, 4, 30).at(0);
    const Bytes whole = encode_group(g, GroupEncoding::cells, 0, &v);
    exact_expect_wire_error(whole, Bytes{}, "empty offsets for an exact body");
    exact_expect_wire_error(whole, Bytes{0}, "offsets for an exact body");
    exact_expect_wire_error(encode_group(g, GroupEncoding::compact_zstd), Bytes{0}, "compact+zstd");
    exact_expect_wire_error(encode_group(g, GroupEncoding::indexed), Bytes{0}, "indexed");
}

TEST(RemoteCellExactMalformed, SeededMutationsOfTheOffsetsDecodeOrThrow) {
    const SteppedBytes* s = exact_stepped_group();
    if (!s) GTEST_SKIP() << "../shared/data is absent: no 16-bit group to step";
    std::mt19937 rng(34);
    for (int i = 0; i < 500; ++i) {
        Bytes m = s->exact;
        m[rng() % m.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
        try {
            decode_two(s->group, &m);  // any offset in a bin is a value: a mesh, not a crash
        } catch (const WireError&) {
        }
    }
}

// Found by the cell_body fuzzer (fuzz/regressions/cell_body/spacing-past-a-float-side): a
// spacing of 8.5e37 passed as finite, and the positions it made were not.
TEST(RemoteCellExactMalformed, ASpacingThatPutsPositionsPastAFloatThrows) {
    const Volume v = make_phantom();
    const Group g = sample_groups(v, kPhantomSkinIso, 4, 30).at(0);
    Bytes body = encode_cell_body(g, v).value();
    // Voxel type u8, dims 3 x i32, then the spacing's x: 1e7 units a side at most.
    for (const float sx : {8.5e37f, 1e7f / 199 * 1.001f}) {
        Bytes b = body;
        std::memcpy(b.data() + 1 + 12, &sx, sizeof sx);
        ByteReader r(b, "cells");
        std::string what;
        try {
            decode_cell_body(r, g.iso);
        } catch (const WireError& e) {
            what = e.what();
        }
        EXPECT_NE(what.find("over the limit"), std::string::npos) << sx << ": " << what;
    }
}

TEST(RemoteCellExact, BitsRoundTripAtEveryWidth) {
    std::mt19937 rng(7);
    for (int bits = 1; bits <= 32; ++bits) {
        std::vector<std::uint64_t> values(37);
        cells::ExactBitsWriter w;
        for (auto& x : values) {
            x = (std::uint64_t{rng()} << 32 | rng()) & ((std::uint64_t{1} << bits) - 1);
            w.put(x, bits);
        }
        const Bytes b = w.take();
        ASSERT_EQ(cells::exact_bits_problem(b, values.size(), bits), "");
        cells::ExactBitsReader r(b);
        for (const auto x : values) ASSERT_EQ(r.get(bits), x) << bits << " bits";
    }
}

}  // namespace
}  // namespace isowall::remote
