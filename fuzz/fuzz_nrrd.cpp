// Harness: the NRRD loader (volume/volume.cpp through Teem). The loader takes a path, so
// the bytes go to files in a per-process folder: everything before a line "@data.raw" is in.nrrd,
// everything after it data.raw beside it (for "data file: data.raw" headers). A volume that loads
// must hold exactly dims x voxel size bytes, every one readable; so must its planes streamed as
// `import` reads them (nrrd_planes).
//
// regressions/nrrd holds one input of each class the loader crashed or hung on before its fix,
// named by class: ascii-* (Teem's ascii reader smashed the stack on a long token), devzero-*
// ("line skip" with "data file: /dev/zero" never ended), datafolder-* (a data file naming a
// folder threw std::runtime_error from MappedFile, not InputError).
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>

#include "core/error.h"
#include "fuzz/fuzz_check.h"
#include "volume/plane_source.h"
#include "volume/volume.h"

namespace {

namespace fs = std::filesystem;
using isowall::fuzz::check;

constexpr std::string_view kDataMark = "\n@data.raw\n";

const fs::path& folder() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("isowall-fuzz-nrrd-" + std::to_string(getpid()));
        fs::create_directories(d);
        std::atexit([] {
            std::error_code ignored;
            fs::remove_all(folder(), ignored);
        });
        return d;
    }();
    return dir;
}

void write(const fs::path& path, std::string_view bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    check(static_cast<bool>(out), "the harness could write its temporary file");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text = isowall::fuzz::as_text(data, size);
    const std::size_t mark = text.find(kDataMark);
    const std::string_view header = text.substr(0, mark);
    write(folder() / "in.nrrd", header);
    write(folder() / "data.raw",
          mark == std::string_view::npos ? "" : text.substr(mark + kDataMark.size()));
    try {
        const isowall::Volume v = isowall::load_nrrd(folder() / "in.nrrd");
        const glm::ivec3 d = v.dims();
        check(d.x >= 2 && d.y >= 2 && d.z >= 2, "a volume of at least 2x2x2 voxels");
        check(v.bytes().size() == v.voxel_count() * isowall::voxel_size(v.type()),
              "the volume holds dims x voxel size bytes");
        std::uint64_t sum = 0;  // read every byte, so a short mapping or buffer shows under ASan
        for (const std::byte b : v.bytes()) sum += static_cast<std::uint64_t>(b);
        check(sum <= 255u * v.bytes().size(), "bytes are bytes");
    } catch (const isowall::InputError&) {
    }
    // The same file streamed as `import` reads it (gzip inflated a slab at a time): every plane
    // readable, or an InputError, whichever slab finds the fault.
    try {
        const auto planes = isowall::nrrd_planes(folder() / "in.nrrd");
        if (!planes) return 0;
        const int depth = planes->dims().z;
        std::uint64_t sum = 0;
        for (int z = 0; z < depth; z += 3) {
            const int z1 = std::min(z + 4, depth);
            const auto got = planes->planes(z, z1);
            check(got.size() == planes->plane_bytes() * std::size_t(z1 - z),
                  "a call holds its planes");
            for (const std::byte b : got) sum += static_cast<std::uint64_t>(b);
            if (z1 == depth) break;
        }
        check(sum < ~std::uint64_t{0}, "bytes are bytes");
    } catch (const isowall::InputError&) {
    }
    return 0;
}
