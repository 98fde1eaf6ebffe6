#pragma once
// Shared by the store tests (store_test.cpp, store_client_test.cpp).
#include <cstdint>
#include <vector>

#include "store/store_writer.h"
#include "tests/test_util.h"
#include "volume/volume.h"

namespace isowall::test {

// A 16-bit volume whose every voxel says where it is, so a voxel from the wrong place shows.
inline Volume pattern_volume(glm::ivec3 dims) {
    std::vector<std::byte> bytes(std::size_t(dims.x) * dims.y * dims.z * 2);
    auto* p = reinterpret_cast<std::uint16_t*>(bytes.data());
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x)
                *p++ = static_cast<std::uint16_t>(x * 7 + y * 131 + z * 1031);
    return Volume(dims, VoxelType::u16, {1.0f, 0.5f, 2.0f}, std::move(bytes), "pattern");
}

// `v` imported as a store in a fresh scratch folder `name` (two threads; `levels` as
// ImportOptions'); returns the store's path.
inline std::filesystem::path import_to(const Volume& v, const std::string& name, int levels = 0) {
    const std::filesystem::path dir = scratch_dir(name);
    store::ImportOptions o;
    o.threads = 2;
    o.levels = levels;
    store::write_store(v, dir / "store", o);
    return dir / "store";
}

}  // namespace isowall::test
