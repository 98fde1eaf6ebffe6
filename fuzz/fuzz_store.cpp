// Harness: a store's metadata (store/store_format.cpp: 0/.zarray and .zattrs, JSON through
// nlohmann's parser). The input is the two texts separated by the first NUL byte. A layout that
// parses must be one the pager can map: its bricks' bytes fit in 64 TiB, the brick is a power of
// two from 8 to 128, every side has at least 2 voxels, the chunk count is the grid's, and the
// spacing is positive and finite.
#include <cmath>
#include <cstdint>
#include <string_view>

#include "core/error.h"
#include "fuzz/fuzz_check.h"
#include "store/store_format.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using isowall::fuzz::check;
    const std::string_view all = isowall::fuzz::as_text(data, size);
    const std::size_t cut = all.find('\0');
    const std::string_view zarray = all.substr(0, cut);
    const std::string_view zattrs = cut == std::string_view::npos ? "" : all.substr(cut + 1);
    try {
        const isowall::store::StoreLayout l = isowall::store::parse_layout(zarray, zattrs, "fuzz");
        check(l.brick() >= 8 && l.brick() <= 128 && (l.brick() & (l.brick() - 1)) == 0,
              "brick a power of two from 8 to 128");
        check(l.dims.x >= 2 && l.dims.y >= 2 && l.dims.z >= 2, "every side at least 2 voxels");
        const long double bytes = static_cast<long double>(l.chunk_count()) * l.brick_bytes();
        check(bytes <= static_cast<long double>(std::uint64_t(1) << 46), "bricks fit in 64 TiB");
        const glm::ivec3 g = l.grid();
        check(static_cast<long double>(g.x) * g.y * g.z == l.chunk_count(), "chunk count");
        for (int a = 0; a < 3; ++a)
            check(std::isfinite(l.spacing[a]) && l.spacing[a] > 0, "spacing positive, finite");
    } catch (const isowall::InputError&) {
    }
    return 0;
}
