#include "common/volume/octree.h"

#include <sys/stat.h>
#include <unistd.h>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>

namespace isowall {

OctreeShape OctreeShape::for_cells(glm::ivec3 cell_dims) {
    OctreeShape s;
    s.cell_dims = cell_dims;
    glm::ivec3 d = glm::max((cell_dims + kLeafCells - 1) / kLeafCells, glm::ivec3(1));
    for (;;) {
        s.levels.push_back({d, s.node_count});
        s.node_count += static_cast<std::size_t>(d.x) * d.y * d.z;
        if (d == glm::ivec3(1)) break;
        d = (d + 1) / 2;
    }
    return s;
}

namespace octree_cache {
namespace {

// Bumped whenever the layout of the nodes or of the header changes.
constexpr char kMagic[8] = {'I', 'S', 'O', 'W', 'O', 'C', 'T', '1'};

struct Header {
    char magic[8];
    std::uint32_t type;
    std::int32_t dims[3];
    std::int32_t leaf_log2;
    std::uint32_t pad;
    std::uint64_t volume_file_size;
    std::int64_t volume_mtime_ns;
    std::uint64_t node_bytes;
    std::uint64_t reserved[2];
};
static_assert(sizeof(Header) == 72);
constexpr std::size_t kNodeOffset = 128;  // keeps the nodes 16-byte aligned for every type

Header header_for(const Key& key, std::size_t node_bytes) {
    Header h{};
    std::memcpy(h.magic, kMagic, sizeof(kMagic));
    h.type = key.type;
    h.dims[0] = key.dims.x;
    h.dims[1] = key.dims.y;
    h.dims[2] = key.dims.z;
    h.leaf_log2 = OctreeShape::kLeafLog2;
    h.volume_file_size = key.volume_file_size;
    h.volume_mtime_ns = key.volume_mtime_ns;
    h.node_bytes = node_bytes;
    return h;
}

}  // namespace

std::optional<Key> key_for(const std::filesystem::path& volume_path, VoxelType type,
                           glm::ivec3 dims) {
    struct stat st {};
    if (::stat(volume_path.c_str(), &st) != 0) return std::nullopt;
    Key k;
    k.type = static_cast<std::uint32_t>(type);
    k.dims = dims;
    k.volume_file_size = static_cast<std::uint64_t>(st.st_size);
    k.volume_mtime_ns =
        static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec;
    return k;
}

std::filesystem::path file_for(const std::filesystem::path& cache_dir,
                               const std::filesystem::path& volume_path) {
    std::error_code ec;
    auto canonical = std::filesystem::weakly_canonical(volume_path, ec);
    if (ec) canonical = std::filesystem::absolute(volume_path);
    std::ostringstream name;
    name << volume_path.stem().string() << "-" << std::hex
         << std::hash<std::string>{}(canonical.string()) << ".octree";
    return cache_dir / name.str();
}

std::optional<std::span<const std::byte>> match(const MappedFile& file, const Key& key,
                                                std::size_t node_bytes, std::string* why) {
    const Header want = header_for(key, node_bytes);
    if (file.size() != kNodeOffset + node_bytes ||
        std::memcmp(file.bytes().data(), &want, sizeof(Header)) != 0) {
        if (why) *why = "cache file is stale (volume changed), rebuilt";
        return std::nullopt;
    }
    return file.bytes().subspan(kNodeOffset, node_bytes);
}

bool write(const std::filesystem::path& file, const Key& key, std::span<const std::byte> nodes,
           std::string* why) {
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    // A per-process temporary name, renamed at the end: ranks that build at once never read a
    // half-written file, and the last rename wins with identical content.
    auto tmp = file;
    tmp += ".tmp" + std::to_string(::getpid());
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        const Header h = header_for(key, nodes.size());
        char pad[kNodeOffset] = {};
        std::memcpy(pad, &h, sizeof(h));
        out.write(pad, kNodeOffset);
        out.write(reinterpret_cast<const char*>(nodes.data()),
                  static_cast<std::streamsize>(nodes.size()));
        if (!out) {
            if (why) *why = "cannot write cache file " + tmp.string();
            std::filesystem::remove(tmp, ec);
            return false;
        }
    }
    std::filesystem::rename(tmp, file, ec);
    if (ec) {
        if (why) *why = "cannot rename cache file: " + ec.message();
        std::filesystem::remove(tmp, ec);
        return false;
    }
    return true;
}

std::filesystem::path default_dir() {
    if (const char* d = std::getenv("ISOWALL_CACHE_DIR"); d && *d) return d;
    if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d)
        return std::filesystem::path(d) / "isowall";
    if (const char* d = std::getenv("HOME"); d && *d)
        return std::filesystem::path(d) / ".cache" / "isowall";
    return std::filesystem::temp_directory_path() / "isowall-cache";
}

}  // namespace octree_cache
}  // namespace isowall
