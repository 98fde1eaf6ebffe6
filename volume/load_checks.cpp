#include "volume/load_checks.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>
#include <sstream>

#include "core/error.h"

namespace isowall {

void check_regular_file(const std::filesystem::path& path, const std::string& where,
                        const std::string& field) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) {
        const int err = errno;
        throw InputError(where, field,
                         quote_bounded(path.string(), 160) + ": " +
                             (err == ENOENT ? std::string("no such file") : std::strerror(err)));
    }
    if (S_ISREG(st.st_mode)) return;
    const char* what = S_ISDIR(st.st_mode)    ? "a folder"
                       : S_ISFIFO(st.st_mode) ? "a FIFO"
                       : S_ISCHR(st.st_mode)  ? "a character device"
                       : S_ISBLK(st.st_mode)  ? "a block device"
                       : S_ISSOCK(st.st_mode) ? "a socket"
                                              : "not a regular file";
    throw InputError(where, field,
                     quote_bounded(path.string(), 160) + " is " + what + ", not a regular file");
}

std::optional<std::uint64_t> checked_product(std::initializer_list<std::uint64_t> factors) {
    std::uint64_t p = 1;
    for (std::uint64_t f : factors)
        if (__builtin_mul_overflow(p, f, &p)) return std::nullopt;
    return p;
}

std::optional<std::uint64_t> checked_sum(std::uint64_t a, std::uint64_t b) {
    std::uint64_t s = 0;
    if (__builtin_add_overflow(a, b, &s)) return std::nullopt;
    return s;
}

glm::ivec3 checked_dims(const std::string& where, const std::string& field,
                        std::span<const std::uint64_t> sizes, VoxelType type) {
    std::ostringstream got;
    for (std::size_t i = 0; i < sizes.size(); ++i) got << (i ? " " : "") << sizes[i];
    bool ok = sizes.size() == 3;
    for (std::uint64_t s : sizes) ok = ok && s >= 2 && s <= static_cast<std::uint64_t>(INT_MAX);
    if (!ok)
        throw InputError(where, field,
                         "expected three sizes from 2 to " + std::to_string(INT_MAX) + ", got " +
                             quote_bounded(got.str()));
    if (!checked_product({sizes[0], sizes[1], sizes[2], voxel_size(type)}))
        throw InputError(where, field,
                         "sizes " + got.str() + " of " + std::string(type_name(type)) +
                             " overflow 64 bits of bytes");
    return {static_cast<int>(sizes[0]), static_cast<int>(sizes[1]), static_cast<int>(sizes[2])};
}

std::uint64_t voxel_bytes(glm::ivec3 dims, VoxelType type) {
    return *checked_product({static_cast<std::uint64_t>(dims.x), static_cast<std::uint64_t>(dims.y),
                             static_cast<std::uint64_t>(dims.z), voxel_size(type)});
}

void check_fits_memory(std::uint64_t bytes, const std::string& where, const std::string& field) {
    const long pages = ::sysconf(_SC_PHYS_PAGES);
    const long page = ::sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0) return;
    const auto memory =
        checked_product({static_cast<std::uint64_t>(pages), static_cast<std::uint64_t>(page)});
    if (memory && bytes > *memory)
        throw InputError(where, field,
                         "the voxels need " + std::to_string(bytes) +
                             " bytes in memory, more than this machine has (" +
                             std::to_string(*memory) + ")");
}

std::vector<std::byte> allocate_voxels(std::uint64_t bytes, const std::string& where,
                                       const std::string& field) {
    check_fits_memory(bytes, where, field);
    try {
        return std::vector<std::byte>(static_cast<std::size_t>(bytes));
    } catch (const std::bad_alloc&) {
        throw InputError(where, field, "cannot allocate " + std::to_string(bytes) + " bytes");
    }
}

void check_size(const std::string& file, std::uint64_t have, std::uint64_t offset,
                std::uint64_t need) {
    const auto total = checked_sum(offset, need);
    if (!total || have < *total) {
        throw InputError(file, "size",
                         "file is shorter than the header says: expected " +
                             (total ? std::to_string(*total)
                                    : std::to_string(offset) + " + " + std::to_string(need)) +
                             " bytes, found " + std::to_string(have));
    }
    if (have > *total) {
        throw InputError(file, "size",
                         "file is longer than the header says: expected " + std::to_string(*total) +
                             " bytes, found " + std::to_string(have));
    }
}

std::string quote_bounded(std::string_view text, std::size_t limit) {
    std::string out;
    for (char c : text) {
        const auto u = static_cast<unsigned char>(c);
        std::string one(1, c);
        if (u < 0x20 || u >= 0x7f || c == '"' || c == '\\') {
            static constexpr char kHex[] = "0123456789abcdef";
            one = {'\\', 'x', kHex[u >> 4], kHex[u & 15]};
        }
        if (out.size() + one.size() > limit) {
            out += "...";
            break;
        }
        out += one;
    }
    return "\"" + out + "\"";
}

std::string spacing_problem(double spacing, int size, int axis) {
    const double side = spacing * std::max(size - 1, 0);
    if (spacing >= FLT_MIN && std::isfinite(side) && side <= kMaxVolumeSide) return {};
    char msg[200];
    std::snprintf(msg, sizeof(msg),
                  "axis %d: spacing %g is unusable (expected a number from %g to %g, so that the "
                  "volume is at most %g object units a side)",
                  axis, spacing, double(FLT_MIN),
                  size > 1 ? kMaxVolumeSide / (size - 1) : double(FLT_MAX), kMaxVolumeSide);
    return msg;
}

}  // namespace isowall
