#include "common/store/store_writer.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include <zstd.h>

#include "common/core/error.h"
#include "common/store/slab_octree.h"

namespace isowall::store {
namespace fs = std::filesystem;

namespace {

struct Range {
    double min = std::numeric_limits<double>::infinity();
    double max = -std::numeric_limits<double>::infinity();
    void merge(double v) {
        if (!std::isfinite(v)) return;
        min = std::min(min, v);
        max = std::max(max, v);
    }
};

Range range_of(std::span<const std::byte> bytes, VoxelType type) {
    return dispatch_voxel_type(type, [&](auto zero) {
        using T = decltype(zero);
        const T* p = reinterpret_cast<const T*>(bytes.data());
        const std::size_t n = bytes.size() / sizeof(T);
        Range r;
        if (n == 0) return r;
        if constexpr (std::is_floating_point_v<T>) {
            for (std::size_t i = 0; i < n; ++i) r.merge(static_cast<double>(p[i]));
        } else {
            const auto [lo, hi] = std::minmax_element(p, p + n);
            r.min = static_cast<double>(*lo);
            r.max = static_cast<double>(*hi);
        }
        return r;
    });
}

// The whole of `bytes` to `file`, or an InputError naming the store and the chunk.
void write_file(const fs::path& file, std::span<const std::byte> bytes, const std::string& store,
                const std::string& key) {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw InputError(store, key, std::string("cannot write: ") + std::strerror(errno));
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const int e = n < 0 ? errno : ENOSPC;
            ::close(fd);
            throw InputError(store, key, std::string("cannot write: ") + std::strerror(e));
        }
        done += static_cast<std::size_t>(n);
    }
    if (::close(fd) != 0)
        throw InputError(store, key, std::string("cannot write: ") + std::strerror(errno));
}

void write_text(const fs::path& file, const std::string& text, const std::string& store,
                const std::string& key) {
    write_file(file, std::as_bytes(std::span(text.data(), text.size())), store, key);
}

// Lets the kernel drop a memory-mapped source's pages of [begin, end) from this process, so an
// import's resident memory stays at a slab, not the volume (they are re-read if touched again).
void release_source_pages(const std::byte* begin, const std::byte* end) {
    const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
    const auto b = (reinterpret_cast<std::uintptr_t>(begin) + page - 1) / page * page;
    const auto e = reinterpret_cast<std::uintptr_t>(end) / page * page;
    if (e > b) ::madvise(reinterpret_cast<void*>(b), e - b, MADV_DONTNEED);
}

// Reads [begin, end) of a memory-mapped source into memory and maps it, in one call rather than
// a fault a page (MADV_POPULATE_READ, Linux 5.14; older kernels fault the pages in as read).
void populate_source_pages(const std::byte* begin, const std::byte* end) {
#ifdef MADV_POPULATE_READ
    const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
    const auto b = reinterpret_cast<std::uintptr_t>(begin) / page * page;
    const auto e = reinterpret_cast<std::uintptr_t>(end);
    if (e > b) ::madvise(reinterpret_cast<void*>(b), e - b, MADV_POPULATE_READ);
#else
    (void)begin, (void)end;
#endif
}

struct TempDir {
    fs::path path;
    bool keep = false;
    ~TempDir() {
        if (keep) return;
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

// The metadata, then the store into place: an old store moves aside first and goes only once
// the new one is in.
void commit(StoreLayout& layout, const Range& range, TempDir& tmp, const fs::path& out,
            const std::string& where) {
    std::error_code ec;
    layout.value_min = range.min <= range.max ? range.min : 0;  // 0, 0: no finite voxel
    layout.value_max = range.min <= range.max ? range.max : 0;
    write_text(tmp.path / ".zgroup", zgroup_json(), where, ".zgroup");
    write_text(tmp.path / "0" / ".zarray", zarray_json(layout), where, "0/.zarray");
    write_text(tmp.path / ".zattrs", zattrs_json(layout), where, ".zattrs");
    fs::path old;
    if (fs::exists(out, ec)) {
        old = tmp.path;
        old += ".old";
        fs::remove_all(old, ec);
        fs::rename(out, old, ec);
        if (ec) throw InputError(where, "--out", "cannot replace the old store: " + ec.message());
    }
    fs::rename(tmp.path, out, ec);
    if (ec)
        throw InputError(where, "--out", "cannot move the new store into place: " + ec.message());
    tmp.keep = true;
    if (!old.empty()) fs::remove_all(old, ec);
}

}  // namespace

fs::path temporary_for(const fs::path& out) {
    const fs::path abs = fs::absolute(out).lexically_normal();
    const fs::path name = abs.has_filename() ? abs.filename() : abs.parent_path().filename();
    const fs::path dir = abs.has_filename() ? abs.parent_path() : abs.parent_path().parent_path();
    std::string hidden(1, '.');  // built in steps: GCC 12 warns falsely on "." + s + "..."
    hidden.append(name.string()).append(".importing");
    return dir / hidden;
}

namespace {

struct Gathered {
    Range range;        // of the voxels in the volume (with want_range)
    bool zero = false;  // every voxel 0: `raw` was not filled
};

// Brick b's voxels, gathered from the volume's rows into `raw` (zeros past the volume's edge, as
// Zarr pads edge chunks); with `want_range`, also the range of the voxels that are in the volume
// (the octree gives it otherwise). Rows of zeros are not copied until a row that is not zero
// comes: a brick of air costs a read of its rows, not a copy.
Gathered gather_brick(const StoreLayout& l, std::span<const std::byte> all, glm::ivec3 b,
                      std::vector<std::byte>& raw, bool want_range) {
    const int side = l.brick();
    const std::size_t size = voxel_size(l.type);
    const std::size_t row_bytes = static_cast<std::size_t>(l.dims.x) * size;
    const glm::ivec3 o = b * side;
    const std::size_t n = static_cast<std::size_t>(std::min(side, l.dims.x - o.x)) * size;
    const bool edge = glm::any(glm::greaterThan(o + side, l.dims));
    raw.resize(l.brick_bytes());
    static constexpr std::byte kZeros[64 * 8] = {};  // a row of the largest brick
    // With want_range every row is copied and measured; without, rows of zeros are skipped.
    Gathered g{{}, !want_range};
    if (!g.zero && edge) std::memset(raw.data(), 0, raw.size());
    for (int z = 0; z < std::min(side, l.dims.z - o.z); ++z)
        for (int y = 0; y < std::min(side, l.dims.y - o.y); ++y) {
            const std::byte* from =
                all.data() +
                ((static_cast<std::size_t>(o.z + z) * l.dims.y + (o.y + y)) * row_bytes +
                 static_cast<std::size_t>(o.x) * size);
            const std::size_t dst = (static_cast<std::size_t>(z) * side + y) * side * size;
            if (g.zero) {
                if (std::memcmp(from, kZeros, n) == 0) continue;
                g.zero = false;  // the rows before were zeros, and so is the padding
                std::memset(raw.data(), 0, edge ? raw.size() : dst);
            }
            std::memcpy(raw.data() + dst, from, n);
            if (!want_range) continue;
            const Range r = range_of(std::span(raw).subspan(dst, n), l.type);
            g.range.merge(r.min);
            g.range.merge(r.max);
        }
    return g;
}

// What the threads of one import share: the tallies, the value range, the first failure.
struct Tally {
    std::mutex mu;
    ImportProgress progress;
    Range range;
    std::string failure;
};

// Compresses and writes rows of bricks of slab bz, taking the next row from `next_row` until none
// is left (rows of air go fast, so threads take rows as they come free); the first failure is
// kept in `tally`.
void write_bricks(const StoreLayout& l, std::span<const std::byte> all, const fs::path& dir,
                  const std::string& where, int bz, std::atomic<int>& next_row, Tally& tally,
                  bool want_range) {
    ZSTD_CCtx* cctx = ZSTD_createCCtx();
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_compressionLevel, l.zstd_level);
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_checksumFlag, 1);
    std::vector<std::byte> raw, packed, zero_frame;
    auto compress = [&](std::vector<std::byte>& to, const std::vector<std::byte>& from,
                        glm::ivec3 b) {
        to.resize(ZSTD_compressBound(from.size()));
        const std::size_t n = ZSTD_compress2(cctx, to.data(), to.size(), from.data(), from.size());
        if (ZSTD_isError(n))
            throw InputError(where, chunk_key(b), std::string("zstd: ") + ZSTD_getErrorName(n));
        to.resize(n);
    };
    try {
        for (int by = next_row++; by < l.grid().y; by = next_row++)
            for (int bx = 0; bx < l.grid().x; ++bx) {
                const glm::ivec3 b(bx, by, bz);
                const Gathered g = gather_brick(l, all, b, raw, want_range);
                // Bricks of nothing but zeros (air around a scan: three in four of the 4x CT
                // head's) all compress to one frame: it is made once and written again.
                if (g.zero && zero_frame.empty()) {
                    raw.assign(l.brick_bytes(), std::byte{0});
                    compress(zero_frame, raw, b);
                }
                if (!g.zero) compress(packed, raw, b);
                const std::vector<std::byte>& frame = g.zero ? zero_frame : packed;
                const std::size_t n = frame.size();
                write_file(dir / chunk_key(b), frame, where, chunk_key(b));
                std::lock_guard lock(tally.mu);
                tally.range.merge(g.range.min);
                tally.range.merge(g.range.max);
                tally.progress.chunks_done += 1;
                tally.progress.bytes_in += l.brick_bytes();
                tally.progress.bytes_out += n;
            }
    } catch (const std::exception& ex) {
        std::lock_guard lock(tally.mu);
        if (tally.failure.empty()) tally.failure = ex.what();
    }
    ZSTD_freeCCtx(cctx);
}

// The store's folders under `dir`: 0/Z/Y for each slab and row of bricks.
void make_folders(const StoreLayout& l, const fs::path& dir, const std::string& where) {
    const glm::ivec3 grid = l.grid();
    std::error_code ec;
    for (int bz = 0; bz < grid.z; ++bz)
        for (int by = 0; by < grid.y; ++by) {
            fs::create_directories(dir / fs::path(chunk_key({0, by, bz})).parent_path(), ec);
            if (ec) throw InputError(where, "--out", "cannot make its folders: " + ec.message());
        }
}

}  // namespace

ImportResult write_store(const Volume& volume, const fs::path& out, const ImportOptions& options) {
    const std::string where = out.string();
    if (volume.bricks())
        throw InputError(volume.source(), "source", "is a store already (copy its folder instead)");
    std::error_code ec;
    if (fs::exists(out, ec) && !options.replace)
        throw InputError(where, "--out", "exists; give --force to replace it");
    if (fs::exists(out, ec) && !is_store(out))
        throw InputError(where, "--out", "exists and is not a store; it is left alone");

    StoreLayout layout = layout_for(volume.dims(), volume.type(), volume.spacing());
    layout.source = volume.source();
    layout.id = new_store_id();
    layout.zstd_level = options.zstd_level;
    const glm::ivec3 grid = layout.grid();
    TempDir tmp{temporary_for(out)};
    fs::remove_all(tmp.path, ec);  // what a stopped run left
    make_folders(layout, tmp.path, where);

    const std::span<const std::byte> all = volume.bytes();
    const std::size_t slice_bytes =
        static_cast<std::size_t>(layout.dims.x) * layout.dims.y * voxel_size(layout.type);
    const int threads = std::max(1, std::min(options.threads, grid.y));
    Tally tally;
    tally.progress.chunks_total = layout.chunk_count();
    const std::unique_ptr<SlabOctree> octree = options.octree ? make_slab_octree(volume) : nullptr;
    FiniteRange finite;
    std::thread reading;
    struct Join {
        std::thread& t;
        ~Join() {
            if (t.joinable()) t.join();
        }
    } join_reading{reading};
    if (volume.mapped())
        populate_source_pages(
            all.data(),
            all.data() + std::min<std::size_t>(all.size(), layout.brick() * slice_bytes));
    for (int bz = 0; bz < grid.z; ++bz) {
        const int z0 = bz * layout.brick(), z1 = std::min(z0 + layout.brick(), layout.dims.z);
        // The next slab is read from disk while this one is compressed.
        if (reading.joinable()) reading.join();
        if (volume.mapped() && z1 < layout.dims.z) {
            const int z2 = std::min(z1 + layout.brick(), layout.dims.z);
            reading = std::thread(populate_source_pages, all.data() + std::size_t(z1) * slice_bytes,
                                  all.data() + std::size_t(z2) * slice_bytes);
        }
        // The slab's rows of bricks split over the threads; each has its buffers and zstd context.
        std::vector<std::thread> pool;
        std::atomic<int> next_row{0};
        for (int t = 1; t < threads; ++t)
            pool.emplace_back(
                [&] { write_bricks(layout, all, tmp.path, where, bz, next_row, tally, !octree); });
        write_bricks(layout, all, tmp.path, where, bz, next_row, tally, !octree);
        for (auto& th : pool) th.join();
        if (!tally.failure.empty()) throw InputError::relayed(tally.failure);
        // The slab's voxels are at hand: its leaves of the octree now, not in a second pass.
        if (octree) finite.merge(octree->add_slab(z0, z1, threads));
        if (volume.mapped())
            release_source_pages(all.data() + std::size_t(z0) * slice_bytes,
                                 all.data() + std::size_t(z1) * slice_bytes);
        if (options.progress) options.progress(tally.progress);
    }
    ImportResult result{layout, tally.progress.bytes_in, tally.progress.bytes_out, {}};
    if (octree) {
        result.octree_note = octree->write(octree_file(tmp.path), content_key(layout), finite);
        const FiniteRange r = octree->range();
        if (r.any) tally.range.merge(r.min), tally.range.merge(r.max);
    }
    if (options.before_commit) options.before_commit(layout, tmp.path);
    layout.bytes = tally.progress.bytes_out;
    commit(layout, tally.range, tmp, out, where);
    result.layout = layout;
    return result;
}

}  // namespace isowall::store
