#include "store/pyramid.h"

namespace isowall::store {

void decimate_plane(std::span<const std::byte> plane0, glm::ivec3 dims0, VoxelType type, int k,
                    glm::ivec3 dims_k, std::byte* to) {
    dispatch_voxel_type(type, [&](auto zero) {
        using T = decltype(zero);
        const T* from = reinterpret_cast<const T*>(plane0.data());
        T* out = reinterpret_cast<T*>(to);
        const std::size_t step = std::size_t{1} << k;
        for (int yk = 0; yk < dims_k.y; ++yk) {
            const T* row = from + (std::size_t(yk) << k) * std::size_t(dims0.x);
            for (int xk = 0; xk < dims_k.x; ++xk) *out++ = row[std::size_t(xk) * step];
        }
    });
}

}  // namespace isowall::store
