#pragma once
// What every reader's test asks of its plane stream (readers/read_volume.h: open_planes):
// the planes `import` streams are the volume read_volume reads, read as the store writer reads
// them (a slab and one plane more, each call starting on the last call's last plane), with no
// more than two calls' planes held at once (one read ahead).
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "readers/read_volume.h"
#include "volume/plane_source.h"

namespace isowall::test {

// The value of voxel i of `bytes` of `type`, as a double.
inline double value_at(const std::byte* bytes, VoxelType type, std::size_t i) {
    return dispatch_voxel_type(type, [&](auto zero) {
        using T = decltype(zero);
        T v;
        std::memcpy(&v, bytes + i * sizeof(T), sizeof(T));
        return double(v);
    });
}

// `source`'s planes, read in slabs of `slab` planes as write_store reads them, equal `whole`'s
// voxels (byte for byte when the types match, value for value when a stream chose a wider type).
inline void expect_planes_equal(PlaneSource& source, const Volume& whole, int slab = 3) {
    ASSERT_EQ(source.dims(), whole.dims()) << whole.source();
    EXPECT_EQ(source.spacing(), whole.spacing()) << whole.source();
    const std::size_t plane = std::size_t(whole.dims().x) * whole.dims().y;
    const int depth = whole.dims().z;
    for (int z0 = 0; z0 < depth; z0 += slab) {
        const int z1 = std::min(z0 + slab + 1, depth);
        const std::span<const std::byte> got = source.planes(z0, z1);
        ASSERT_EQ(got.size(), plane * std::size_t(z1 - z0) * voxel_size(source.type()));
        const std::byte* want =
            whole.bytes().data() + plane * std::size_t(z0) * voxel_size(whole.type());
        if (source.type() == whole.type()) {
            ASSERT_EQ(std::memcmp(got.data(), want, got.size()), 0)
                << whole.source() << ": planes " << z0 << " to " << z1 - 1;
            continue;
        }
        for (std::size_t i = 0; i < plane * std::size_t(z1 - z0); ++i)
            ASSERT_EQ(value_at(got.data(), source.type(), i), value_at(want, whole.type(), i))
                << whole.source() << ": voxel " << i << " of planes from " << z0;
    }
    if (auto* decoded = dynamic_cast<DecodedPlanes*>(&source)) {
        // This call's planes and as many read ahead.
        EXPECT_LE(decoded->peak_bytes(),
                  2 * plane * std::size_t(slab + 1) * voxel_size(source.type()));
    }
}

// open_planes(path) streams what read_volume(path) reads (`streams` false: it is a format that
// read_volume maps, and open_planes says so with null).
inline void expect_streams_alike(const std::string& path, bool streams = true) {
    const Volume whole = formats::read_volume(path, std::nullopt);
    const std::unique_ptr<PlaneSource> planes = formats::open_planes(path, std::nullopt);
    ASSERT_EQ(planes != nullptr, streams) << path;
    if (planes) expect_planes_equal(*planes, whole);
}

}  // namespace isowall::test
