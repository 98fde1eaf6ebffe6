// The packing of a cells group (remote/group_codec.h): the body as it is, or through zstd where
// that is smaller.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "remote/cell_codec.h"
#include "remote/group_codec.h"
#include "remote/sample_groups.h"
#include "volume/phantom.h"

namespace isowall::remote {
namespace {

using Bytes = std::vector<std::uint8_t>;

// The packing byte after a cells group's header (group_codec.h): a range-coded body goes as it is
// (zstd made it larger), a float volume's byte planes through zstd where that is smaller; both
// round trip, and a packing past 1 or a byte past the body is refused by name.
TEST(RemoteCellCodec, ABodyGoesThroughZstdOnlyWhereThatIsSmaller) {
    static const Volume v = make_phantom();
    const auto view = v.view<std::uint8_t>();
    std::vector<std::byte> floats(v.voxel_count() * sizeof(float));
    for (std::size_t i = 0; i < v.voxel_count(); ++i) {
        const float f = static_cast<float>(view.data[i]);
        std::memcpy(floats.data() + i * sizeof(float), &f, sizeof f);
    }
    const Volume vf(v.dims(), VoxelType::f32, v.spacing(), std::move(floats), "float phantom");
    constexpr std::size_t kPacking = 2 + 29;  // version, encoding, the group header
    for (const Volume* volume : {&v, &vf}) {
        const bool is_float = volume == &vf;
        const Group g = sample_groups(*volume, kPhantomSkinIso, 24, 2000).at(3);
        const Bytes bytes = encode_group(g, GroupEncoding::cells, 0, volume);
        const auto body = encode_cell_body(g, *volume);
        ASSERT_TRUE(body.has_value());
        ASSERT_EQ(encoding_of(bytes), GroupEncoding::cells);
        EXPECT_EQ(bytes.at(kPacking), is_float ? 1 : 0) << volume->source();
        if (is_float)
            EXPECT_LT(bytes.size(), kPacking + 1 + body->size()) << "zstd packs the planes";
        else
            EXPECT_EQ(bytes.size(), kPacking + 1 + body->size()) << "the body as it is";
        ByteReader r(*body, "cells");
        const Mesh want = decode_cell_body(r, g.iso);
        const Mesh got = decode_group(bytes).mesh;
        EXPECT_EQ(got.indices, want.indices) << volume->source();
        EXPECT_EQ(got.positions, want.positions) << volume->source();
        EXPECT_EQ(got.normals, want.normals) << volume->source();
        EXPECT_GT(got.triangle_count(), 0u);
        Bytes bad = bytes;
        bad[kPacking] = 2;
        EXPECT_THROW(
            {
                try {
                    decode_group(bad);
                } catch (const WireError& e) {
                    EXPECT_NE(std::string(e.what()).find("cells packing: expected 0 (as it is) or "
                                                         "1 (zstd), got 2"),
                              std::string::npos)
                        << e.what();
                    throw;
                }
            },
            WireError);
        Bytes longer = bytes;
        longer.push_back(0);
        EXPECT_THROW(decode_group(longer), WireError) << volume->source() << ": a trailing byte";
    }
}

}  // namespace
}  // namespace isowall::remote
