#pragma once
// For harnesses of readers that take a path: a per-process temporary folder the fuzzer's bytes
// are written into, and the check every volume that loads must pass.
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "core/error.h"
#include "fuzz/fuzz_check.h"
#include "volume/volume.h"

namespace isowall::fuzz {

inline const std::filesystem::path& scratch_folder(const std::string& name) {
    static const std::filesystem::path dir = [&] {
        std::filesystem::path d = std::filesystem::temp_directory_path() /
                                  ("isowall-fuzz-" + name + "-" + std::to_string(getpid()));
        std::filesystem::create_directories(d);
        static const std::filesystem::path keep = d;
        std::atexit([] {
            std::error_code ignored;
            std::filesystem::remove_all(keep, ignored);
        });
        return d;
    }();
    return dir;
}

inline void write_file(const std::filesystem::path& path, std::string_view bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    check(static_cast<bool>(out), "the harness could write its temporary file");
}

// A volume that loads holds dims x voxel size bytes, every one readable, and its orientation is
// a rotation (the readers reverse a mirrored axis).
inline void check_volume(const Volume& v) {
    const glm::ivec3 d = v.dims();
    check(d.x >= 2 && d.y >= 2 && d.z >= 2, "a volume of at least 2x2x2 voxels");
    check(v.bytes().size() == v.voxel_count() * voxel_size(v.type()),
          "the volume holds dims x voxel size bytes");
    std::uint64_t sum = 0;
    for (const std::byte b : v.bytes()) sum += static_cast<std::uint64_t>(b);
    check(sum <= 255u * v.bytes().size(), "bytes are bytes");
}

// The fuzzer's bytes as the file `name` in this harness's folder, read as --volume reads it: a
// volume that loads passes check_volume, an InputError is the reader saying no.
template <class Read>
void read_as_file(const std::string& harness, const std::string& name, const std::uint8_t* data,
                  std::size_t size, Read read) {
    const auto path = scratch_folder(harness) / name;
    write_file(path, as_text(data, size));
    try {
        check_volume(read(path.string()));
    } catch (const InputError&) {
    }
}

}  // namespace isowall::fuzz
