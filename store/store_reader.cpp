#include "store/store_reader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include <zstd.h>

#include "core/error.h"

namespace isowall::store {
namespace fs = std::filesystem;

std::string read_metadata(const fs::path& file, const std::string& store, const std::string& name) {
    constexpr std::uintmax_t kMaxMeta = 1 << 20;
    std::error_code ec;
    const auto size = fs::file_size(file, ec);
    if (ec) throw InputError(store, name, "cannot read: " + ec.message());
    if (size > kMaxMeta) throw InputError(store, name, "larger than 1 MiB: not store metadata");
    std::ifstream in(file, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    if (!in && !in.eof()) throw InputError(store, name, "cannot read");
    return s.str();
}

namespace {

struct Fd {
    int fd = -1;
    ~Fd() {
        if (fd >= 0) ::close(fd);
    }
};

}  // namespace

StoreReader::StoreReader(const fs::path& store) : path_(store) {
    const std::string where = store.string();
    if (!is_store(store))
        throw InputError(where, "store", "not a store (no .zattrs and 0/.zarray in the folder)");
    zarray_ = read_metadata(store / "0" / ".zarray", where, "0/.zarray");
    zattrs_ = read_metadata(store / ".zattrs", where, ".zattrs");
    layout_ = parse_layout(zarray_, zattrs_, where);
    for (int k = 1; k < layout_.levels; ++k) {
        const std::string key = std::to_string(k) + "/.zarray";
        check_level(read_metadata(store / key, where, key), layout_, k, where);
    }
    check_chunks(store, where);
}

// Every chunk file is listed in its row's folder (one readdir a row of bricks, not a stat a
// chunk: a store of 120,000 chunks opens in a few milliseconds). Their sizes are summed only for
// a store that did not record them.
void StoreReader::check_chunks(const fs::path& store, const std::string& where) {
    for (int k = 0; k < layout_.levels; ++k) check_level_chunks(store, where, k);
    bytes_on_disk_ = layout_.bytes;
    if (bytes_on_disk_ != 0) return;
    for (std::size_t i = 0; i < layout_.chunk_count(); ++i) {
        struct stat st {};
        const std::string key = chunk_key(layout_.brick_at(i));
        if (::stat((store / key).c_str(), &st) != 0 || !S_ISREG(st.st_mode) || st.st_size == 0)
            throw InputError(where, key, "chunk is not a non-empty file");
        bytes_on_disk_ += static_cast<std::uint64_t>(st.st_size);
    }
}

void StoreReader::check_level_chunks(const fs::path& store, const std::string& where, int k) {
    const glm::ivec3 grid = layout_.level(k).grid();
    std::vector<char> seen(static_cast<std::size_t>(grid.x));
    for (int bz = 0; bz < grid.z; ++bz)
        for (int by = 0; by < grid.y; ++by) {
            std::fill(seen.begin(), seen.end(), 0);
            const fs::path row = store / fs::path(chunk_key({0, by, bz}, k)).parent_path();
            std::error_code ec;
            for (fs::directory_iterator it(row, ec), end; !ec && it != end; it.increment(ec)) {
                const std::string name = it->path().filename().string();
                char* stop = nullptr;
                const long x = std::strtol(name.c_str(), &stop, 10);
                if (*stop == '\0' && !name.empty() && x >= 0 && x < grid.x && !it->is_directory(ec))
                    seen[static_cast<std::size_t>(x)] = 1;
            }
            for (int bx = 0; bx < grid.x; ++bx)
                if (!seen[static_cast<std::size_t>(bx)])
                    throw InputError(where, chunk_key({bx, by, bz}, k),
                                     "chunk missing: no such file");
        }
}

StoreReader::StoreReader(const std::string& name, const std::string& zarray,
                         const std::string& zattrs, std::uint64_t bytes_on_disk, ChunkFetch fetch)
    : path_(name),
      zarray_(zarray),
      zattrs_(zattrs),
      layout_(parse_layout(zarray, zattrs, name)),
      bytes_on_disk_(bytes_on_disk),
      fetch_(std::move(fetch)) {}

std::vector<std::byte> StoreReader::read_packed(glm::ivec3 b, int level) const {
    const std::string where = path_.string(), key = chunk_key(b, level);
    if (fetch_) throw InputError(where, key, "internal: the store is not read on this host");
    Fd f;
    // Without blocking: a FIFO put where a chunk belongs would wait for a writer for ever. The
    // flag does nothing to a regular file's reads, and nothing else is read.
    f.fd = ::open((path_ / key).c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (f.fd < 0) throw InputError(where, key, std::string("cannot open: ") + std::strerror(errno));
    struct stat st {};
    if (::fstat(f.fd, &st) != 0 || !S_ISREG(st.st_mode))
        throw InputError(where, key, "chunk is not a file");
    // zstd never expands data by more than a small bound; a chunk larger than that is not ours.
    const std::size_t size = static_cast<std::size_t>(st.st_size);
    if (size > ZSTD_compressBound(layout_.brick_bytes()) + 64)
        throw InputError(where, key, "chunk larger than its voxels could compress to");
    std::vector<std::byte> packed(size);
    std::size_t got = 0;
    while (got < size) {
        const ssize_t n = ::read(f.fd, packed.data() + got, size - got);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0)
            throw InputError(where, key, std::string("cannot read: ") + std::strerror(errno));
        if (n == 0) break;
        got += static_cast<std::size_t>(n);
    }
    if (got != size) throw InputError(where, key, "chunk shorter than its size (truncated)");
    return packed;
}

void StoreReader::prefetch(glm::ivec3 b) const {
    if (fetch_) return;
    Fd f;
    f.fd = ::open((path_ / chunk_key(b)).c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (f.fd >= 0) ::posix_fadvise(f.fd, 0, 0, POSIX_FADV_WILLNEED);
}

std::size_t StoreReader::read_chunk(glm::ivec3 b, std::span<std::byte> out, int level) const {
    const std::string where = path_.string(), key = chunk_key(b, level);
    const std::size_t want = layout_.brick_bytes();
    if (out.size() != want) throw InputError(where, key, "internal: wrong chunk buffer size");
    if (level < 0 || level >= layout_.levels || (level > 0 && fetch_))
        throw InputError(where, key, "internal: no such level here");
    const std::vector<std::byte> packed = fetch_ ? fetch_(b) : read_packed(b, level);
    const std::size_t size = packed.size();
    if (size > ZSTD_compressBound(want) + 64)
        throw InputError(where, key, "chunk larger than its voxels could compress to");
    const unsigned long long content = ZSTD_getFrameContentSize(packed.data(), size);
    if (content == ZSTD_CONTENTSIZE_ERROR)
        throw InputError(where, key, "not a zstd frame (a damaged or foreign chunk)");
    if (content != ZSTD_CONTENTSIZE_UNKNOWN && content != want)
        throw InputError(where, key,
                         "holds " + std::to_string(content) + " bytes, the layout needs " +
                             std::to_string(want) + " (metadata and chunks disagree)");
    const std::size_t n = ZSTD_decompress(out.data(), out.size(), packed.data(), size);
    if (ZSTD_isError(n))
        throw InputError(
            where, key,
            std::string("cannot decompress (") + ZSTD_getErrorName(n) + "): the chunk is damaged");
    if (n != want)
        throw InputError(where, key,
                         "decompressed to " + std::to_string(n) + " bytes, the layout needs " +
                             std::to_string(want));
    return size;
}

}  // namespace isowall::store
