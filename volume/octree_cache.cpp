#include "volume/octree.h"

#include <sched.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "core/fatal.h"
#include "files/output_files.h"

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
constexpr char kMagic[8] = {'I', 'S', 'O', 'W', 'O', 'C', 'T', '3'};

struct Header {
    char magic[8];
    std::uint32_t type;
    std::int32_t dims[3];
    std::int32_t leaf_log2;
    std::uint32_t pad;
    std::uint64_t sources;  // Key::sources
    std::uint64_t node_bytes;
    // What the nodes decide, after the key. The checksum covers the value range too: every byte
    // of the file that the program trusts is either in the key or under the checksum.
    std::uint64_t content_checksum;  // content_checksum(): the node bytes, then the range fields
    double finite_min, finite_max;   // FiniteRange, when has_finite is 1
    std::uint64_t has_finite;
};
static_assert(sizeof(Header) == 80);
constexpr std::size_t kNodeOffset = 128;  // keeps the nodes 16-byte aligned for every type

// The header without what only the nodes decide (their checksum and value range): two headers
// for one key compare equal on these bytes.
constexpr std::size_t kKeyBytes = offsetof(Header, content_checksum);

Header header_for(const Key& key, std::size_t node_bytes) {
    Header h{};
    std::memcpy(h.magic, kMagic, sizeof(kMagic));
    h.type = key.type;
    h.dims[0] = key.dims.x;
    h.dims[1] = key.dims.y;
    h.dims[2] = key.dims.z;
    h.leaf_log2 = OctreeShape::kLeafLog2;
    h.sources = key.sources;
    h.node_bytes = node_bytes;
    return h;
}

constexpr std::uint64_t kFnvOffset = 14695981039346656037ull;
constexpr std::uint64_t kFnvPrime = 1099511628211ull;

std::uint64_t fnv_mix(std::uint64_t h, std::uint64_t word) {
    return (h ^ word) * kFnvPrime;
}

std::uint64_t fnv_string(std::uint64_t h, const std::string& s) {
    for (unsigned char c : s) h = fnv_mix(h, c);
    return fnv_mix(h, s.size());
}

std::uint64_t bits_of(double v) {
    std::uint64_t w;
    std::memcpy(&w, &v, sizeof(w));
    return w;
}

}  // namespace

std::uint64_t checksum(std::span<const std::byte> bytes) {
    std::uint64_t h = kFnvOffset;
    std::size_t i = 0;
    for (; i + 8 <= bytes.size(); i += 8) {
        std::uint64_t w;
        std::memcpy(&w, bytes.data() + i, 8);
        h = fnv_mix(h, w);
    }
    std::uint64_t tail = 0;
    if (i < bytes.size()) std::memcpy(&tail, bytes.data() + i, bytes.size() - i);
    return fnv_mix(fnv_mix(h, tail), bytes.size());
}

std::uint64_t content_checksum(std::span<const std::byte> nodes, double finite_min,
                               double finite_max, std::uint64_t has_finite) {
    std::uint64_t h = checksum(nodes);
    for (std::uint64_t w : {bits_of(finite_min), bits_of(finite_max), has_finite})
        h = fnv_mix(h, w);
    return h;
}

std::optional<Key> key_for(const std::vector<std::filesystem::path>& files, VoxelType type,
                           glm::ivec3 dims) {
    Key k;
    k.type = static_cast<std::uint32_t>(type);
    k.dims = dims;
    std::uint64_t h = kFnvOffset;
    for (const auto& f : files) {
        struct stat st {};
        if (::stat(f.c_str(), &st) != 0) return std::nullopt;
        std::error_code ec;
        auto canonical = std::filesystem::weakly_canonical(f, ec);
        h = fnv_string(h, (ec ? std::filesystem::absolute(f) : canonical).string());
        for (std::int64_t v : {std::int64_t(st.st_size), std::int64_t(st.st_ino),
                               std::int64_t(st.st_mtim.tv_sec), std::int64_t(st.st_mtim.tv_nsec),
                               std::int64_t(st.st_ctim.tv_sec), std::int64_t(st.st_ctim.tv_nsec)})
            h = fnv_mix(h, static_cast<std::uint64_t>(v));
    }
    k.sources = h;
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

std::optional<Hit> match(const MappedFile& file, const Key& key, std::size_t node_bytes,
                         std::string* why, bool check_content) {
    const Header want = header_for(key, node_bytes);
    Header have{};
    if (file.size() >= sizeof(Header)) std::memcpy(&have, file.bytes().data(), sizeof(Header));
    if (file.size() < sizeof(Header) || std::memcmp(&have, &want, kKeyBytes) != 0) {
        if (why) *why = "cache file is stale (volume changed), rebuilt";
        return std::nullopt;
    }
    if (file.size() != kNodeOffset + node_bytes) {
        if (why) *why = "cache file is truncated or padded, rebuilt";
        return std::nullopt;
    }
    const auto nodes = file.bytes().subspan(kNodeOffset, node_bytes);
    FiniteRange range;
    if (have.has_finite) range.merge(have.finite_min), range.merge(have.finite_max);
    const bool range_ok = (have.has_finite != 0) == range.any && have.has_finite <= 1;
    const std::uint64_t sum =
        check_content ? content_checksum(nodes, have.finite_min, have.finite_max, have.has_finite)
                      : have.content_checksum;
    if (sum != have.content_checksum || !range_ok) {
        if (why) *why = "cache file is damaged (checksum mismatch), rebuilt";
        return std::nullopt;
    }
    return Hit{nodes, range};
}

namespace {

// The content check of a mapped octree, on a thread of idle priority (it runs on cores the frame
// leaves free). Joined when the octree goes: a program never ends with its octree unchecked.
struct BackgroundCheck {
    std::thread thread;
    ~BackgroundCheck() { thread.join(); }
};

void check_content(const MappedFile& file, const std::filesystem::path& path,
                   std::size_t node_bytes) {
    sched_param param{};
    ::sched_setscheduler(0, SCHED_IDLE, &param);  // this thread only (Linux)
    Header have{};
    std::memcpy(&have, file.bytes().data(), sizeof(Header));
    const auto nodes = file.bytes().subspan(kNodeOffset, node_bytes);
    if (content_checksum(nodes, have.finite_min, have.finite_max, have.has_finite) ==
        have.content_checksum)
        return;
    // A damaged octree would hide surface: the program ends here, as on a damaged chunk.
    end_with_error(path.string() +
                   ": the octree is damaged (checksum mismatch); delete it and open the volume "
                   "again to rebuild it");
}

}  // namespace

std::shared_ptr<void> check_in_background(std::shared_ptr<const MappedFile> file,
                                          const std::filesystem::path& path,
                                          std::size_t node_bytes) {
    auto check = std::make_shared<BackgroundCheck>();
    check->thread = std::thread(
        [file = std::move(file), path, node_bytes] { check_content(*file, path, node_bytes); });
    return check;
}

bool write(const std::filesystem::path& file, const Key& key, std::span<const std::byte> nodes,
           const FiniteRange& range, std::string* why) {
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    // Through the one temp-then-rename helper: ranks that build at once never read a half-written
    // file (each writes its own temporary, the last rename wins with identical content), and a
    // signal mid-write leaves no temporary. A cache that cannot be written is a note, not an error.
    try {
        write_output(file, [&](const std::filesystem::path& tmp) {
            std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
            Header h = header_for(key, nodes.size());
            h.has_finite = range.any ? 1 : 0;
            h.finite_min = range.min;
            h.finite_max = range.max;
            h.content_checksum = content_checksum(nodes, h.finite_min, h.finite_max, h.has_finite);
            char pad[kNodeOffset] = {};
            std::memcpy(pad, &h, sizeof(h));
            out.write(pad, kNodeOffset);
            out.write(reinterpret_cast<const char*>(nodes.data()),
                      static_cast<std::streamsize>(nodes.size()));
            if (!out) throw std::runtime_error("cannot write cache file " + file.string());
        });
    } catch (const std::exception& e) {
        if (why) *why = e.what();
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
