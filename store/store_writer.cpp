#include "store/store_writer.h"

#include <fcntl.h>
#include <sys/file.h>
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

#include "core/error.h"
#include "store/pyramid.h"
#include "store/slab_octree.h"
#include "store/source_pages.h"
#include "volume/load_checks.h"

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

// The folder the store is built in, held for the whole import: made (or a stopped run's taken
// over) and locked (flock), so that a second import into the same --out is refused rather than
// writing its chunks among the first's. Removed at the end unless it became the store.
struct TempDir {
    fs::path path;
    int fd = -1;
    bool keep = true;  // until it is ours
    ~TempDir() {
        std::error_code ec;
        if (!keep) fs::remove_all(path, ec);
        if (fd >= 0) ::close(fd);
    }
};

void hold(TempDir& tmp, const std::string& where) {
    std::error_code ec;
    fs::create_directory(tmp.path, ec);  // an existing one is a stopped run's, or another's
    if (ec)
        throw InputError(where, "--out", "cannot make " + tmp.path.string() + ": " + ec.message());
    tmp.fd = ::open(tmp.path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (tmp.fd < 0)
        throw InputError(where, "--out",
                         "cannot open " + tmp.path.string() + ": " + std::strerror(errno));
    if (::flock(tmp.fd, LOCK_EX | LOCK_NB) != 0)
        throw InputError(where, "--out",
                         "another import is writing this store now (" +
                             tmp.path.filename().string() + " is locked)");
    tmp.keep = false;
    for (const fs::directory_entry& e : fs::directory_iterator(tmp.path, ec))
        fs::remove_all(e.path(), ec);  // what a stopped run left
}

// Why `--force` may not replace the folder `out`, or empty: only a store isowall wrote is
// replaced, holding nothing but a store's own files (its metadata, its levels' folders and its
// octree), so that no file of the user's goes with it.
std::string unreplaceable(const fs::path& out) {
    std::error_code ec;
    if (!fs::is_directory(out, ec)) return "exists and is not a folder";
    for (const char* name : {".zattrs", "0/.zarray"})
        if (!fs::is_regular_file(out / name, ec))
            return std::string("is not a store isowall wrote (no ") + name + ")";
    StoreLayout layout;
    try {
        const std::string at = out.string();
        layout = parse_layout(read_metadata(out / "0" / ".zarray", at, "0/.zarray"),
                              read_metadata(out / ".zattrs", at, ".zattrs"), at);
    } catch (const InputError& e) {
        std::string why = e.what();
        if (why.rfind(out.string() + ": ", 0) == 0) why.erase(0, out.string().size() + 2);
        return "is not a store isowall wrote (" + why + ")";
    }
    for (const fs::directory_entry& e : fs::directory_iterator(out, ec)) {
        const std::string name = e.path().filename().string();
        const bool level = name.find_first_not_of("0123456789") == std::string::npos &&
                           name.size() <= 2 && std::stoi(name) < layout.levels &&
                           e.is_directory(ec) && !e.is_symlink(ec);
        const bool own =
            name == ".zgroup" || name == ".zattrs" || e.path() == octree_file(out) || level;
        if (!own) return "holds " + quote_bounded(name) + ", which is not part of a store";
    }
    return {};
}

// The metadata, then the store into place: an old store moves aside first and goes only once
// the new one is in.
void commit(StoreLayout& layout, const Range& range, TempDir& tmp, const fs::path& out,
            const std::string& where) {
    std::error_code ec;
    layout.value_min = range.min <= range.max ? range.min : 0;  // 0, 0: no finite voxel
    layout.value_max = range.min <= range.max ? range.max : 0;
    write_text(tmp.path / ".zgroup", zgroup_json(), where, ".zgroup");
    for (int k = 0; k < layout.levels; ++k) {
        const std::string key = std::to_string(k) + "/.zarray";
        write_text(tmp.path / key, zarray_json(layout.level(k)), where, key);
    }
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
// `all` holds the volume's rows from z_base on (a level's slab: pyramid.h).
Gathered gather_brick(const StoreLayout& l, std::span<const std::byte> all, int z_base,
                      glm::ivec3 b, std::vector<std::byte>& raw, bool want_range) {
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
                ((static_cast<std::size_t>(o.z + z - z_base) * l.dims.y + (o.y + y)) * row_bytes +
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
    std::uint64_t level0_bytes = 0;
    Range range;
    std::string failure;
};

// Which slab of which level write_bricks writes, from which voxels: `all` holds the level's rows
// from z_base on.
struct SlabJob {
    const StoreLayout& l;  // the level's layout
    int level;
    std::span<const std::byte> all;
    int z_base;
    int bz;
};

// Compresses and writes rows of bricks of a slab, taking the next row from `next_row` until none
// is left (rows of air go fast, so threads take rows as they come free); the first failure is
// kept in `tally`.
void write_bricks(const SlabJob& job, const fs::path& dir, const std::string& where,
                  std::atomic<int>& next_row, Tally& tally, bool want_range) {
    const StoreLayout& l = job.l;
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
                const glm::ivec3 b(bx, by, job.bz);
                const Gathered g = gather_brick(l, job.all, job.z_base, b, raw, want_range);
                // Bricks of nothing but zeros (air around a scan: three in four of the 4x CT
                // head's) all compress to one frame: it is made once and written again.
                if (g.zero && zero_frame.empty()) {
                    raw.assign(l.brick_bytes(), std::byte{0});
                    compress(zero_frame, raw, b);
                }
                if (!g.zero) compress(packed, raw, b);
                const std::vector<std::byte>& frame = g.zero ? zero_frame : packed;
                const std::size_t n = frame.size();
                const std::string key = chunk_key(b, job.level);
                write_file(dir / key, frame, where, key);
                std::lock_guard lock(tally.mu);
                if (job.level == 0) tally.level0_bytes += n;
                tally.range.merge(g.range.min);
                tally.range.merge(g.range.max);
                tally.progress.chunks_done += 1;
                if (job.level == 0) tally.progress.bytes_in += l.brick_bytes();
                tally.progress.bytes_out += n;
            }
    } catch (const std::exception& ex) {
        std::lock_guard lock(tally.mu);
        if (tally.failure.empty()) tally.failure = ex.what();
    }
    ZSTD_freeCCtx(cctx);
}

// The store's folders under `dir`: K/Z/Y for each level, slab and row of bricks.
void make_folders(const StoreLayout& l, const fs::path& dir, const std::string& where) {
    std::error_code ec;
    for (int k = 0; k < l.levels; ++k) {
        const glm::ivec3 grid = l.level(k).grid();
        for (int bz = 0; bz < grid.z; ++bz)
            for (int by = 0; by < grid.y; ++by) {
                fs::create_directories(dir / fs::path(chunk_key({0, by, bz}, k)).parent_path(), ec);
                if (ec)
                    throw InputError(where, "--out", "cannot make its folders: " + ec.message());
            }
    }
}

// Compresses and writes one slab over `threads` threads; throws the first failure.
void write_slab(const SlabJob& job, int threads, const fs::path& dir, const std::string& where,
                Tally& tally, bool want_range) {
    std::vector<std::thread> pool;
    std::atomic<int> next_row{0};
    for (int t = 1; t < threads; ++t)
        pool.emplace_back([&] { write_bricks(job, dir, where, next_row, tally, want_range); });
    write_bricks(job, dir, where, next_row, tally, want_range);
    for (auto& th : pool) th.join();
    if (!tally.failure.empty()) throw InputError::relayed(tally.failure);
}

// Level k >= 1 of the pyramid (store_format.h): every 2^k-th voxel of the level-0 slabs as they
// pass, gathered into a slab of the level's own bricks and written when it is full. Memory: a
// slab of level 1 is a quarter of one of level 0, and the levels above it add a third of that.
class LevelSlab {
  public:
    LevelSlab(const StoreLayout& level0, int k)
        : k_(k),
          l_(level0.level(k)),
          plane_(std::size_t(l_.dims.x) * l_.dims.y * voxel_size(l_.type)),
          rows_(plane_ * std::size_t(l_.brick())) {}

    // Takes level-0 planes [z0, z1) of `planes` (which holds the level-0 planes from z0 on);
    // writes each slab filled.
    void add(std::span<const std::byte> planes, glm::ivec3 dims0, int z0, int z1, int threads,
             const fs::path& dir, const std::string& where, Tally& tally) {
        const std::size_t plane0 = std::size_t(dims0.x) * dims0.y * voxel_size(l_.type);
        const int step = 1 << k_;
        for (int z = (z0 + step - 1) / step * step; z < z1; z += step) {
            const int zk = z >> k_;
            decimate_plane(planes.subspan(std::size_t(z - z0) * plane0, plane0), dims0, l_.type, k_,
                           l_.dims, rows_.data() + std::size_t(zk - bz_ * l_.brick()) * plane_);
            if (zk == (bz_ + 1) * l_.brick() - 1 || zk == l_.dims.z - 1) {
                write_slab({l_, k_, rows_, bz_ * l_.brick(), bz_}, threads, dir, where, tally,
                           false);
                ++bz_;
            }
        }
    }

  private:
    int k_;
    StoreLayout l_;
    std::size_t plane_;  // bytes of one z plane of the level
    std::vector<std::byte> rows_;
    int bz_ = 0;  // the level's slab being filled
};

}  // namespace

ImportResult write_store(const Volume& volume, const fs::path& out, const ImportOptions& options) {
    if (volume.bricks())
        throw InputError(volume.source(), "source", "is a store already (copy its folder instead)");
    VolumePlanes planes(volume);
    return write_store(planes, out, options);
}

ImportResult write_store(PlaneSource& source, const fs::path& out, const ImportOptions& options) {
    const std::string where = out.string();
    std::error_code ec;
    const auto exists = [&] {
        return fs::symlink_status(out, ec).type() != fs::file_type::not_found;
    };
    if (exists() && !options.replace)  // before any folder is made; again under the lock
        throw InputError(where, "--out", "exists; give --force to replace it");
    TempDir tmp{temporary_for(out)};
    hold(tmp, where);
    // Under the lock: a store another import finished meanwhile counts as existing.
    if (exists()) {
        if (!options.replace)
            throw InputError(where, "--out", "exists; give --force to replace it");
        if (const std::string why = unreplaceable(out); !why.empty())
            throw InputError(where, "--out", why + "; it is left alone");
    }

    StoreLayout layout = layout_for(source.dims(), source.type(), source.spacing());
    layout.source = source.source();
    layout.id = new_store_id();
    layout.zstd_level = options.zstd_level;
    layout.levels = options.levels > 0
                        ? std::min(options.levels, levels_for(layout.dims, layout.brick_log2))
                        : levels_for(layout.dims, layout.brick_log2);
    const glm::ivec3 grid = layout.grid();
    make_folders(layout, tmp.path, where);

    const int threads = std::max(1, std::min(options.threads, grid.y));
    Tally tally;
    for (int k = 0; k < layout.levels; ++k)
        tally.progress.chunks_total += layout.level(k).chunk_count();
    std::vector<LevelSlab> pyramid;
    for (int k = 1; k < layout.levels; ++k) pyramid.emplace_back(layout, k);
    const std::unique_ptr<SlabOctree> octree =
        options.octree ? make_slab_octree(layout.dims, layout.type) : nullptr;
    FiniteRange finite;
    const auto check_stop = [&] {
        if (options.stop && options.stop->load()) throw ImportStopped(tmp.path);
    };
    for (int bz = 0; bz < grid.z; ++bz) {
        check_stop();
        const int z0 = bz * layout.brick(), z1 = std::min(z0 + layout.brick(), layout.dims.z);
        // The slab's planes and the next one's first, which the octree's last leaves reach.
        const std::span<const std::byte> planes =
            source.planes(z0, std::min(z1 + 1, layout.dims.z));
        // The slab's rows of bricks split over the threads; each has its buffers and zstd context.
        write_slab({layout, 0, planes, z0, bz}, threads, tmp.path, where, tally, !octree);
        for (LevelSlab& level : pyramid)
            level.add(planes, layout.dims, z0, z1, threads, tmp.path, where, tally);
        // The slab's voxels are at hand: its leaves of the octree now, not in a second pass.
        if (octree) finite.merge(octree->add_slab(planes, z0, z1, threads));
        if (options.progress) options.progress(tally.progress);
    }
    ImportResult result{layout, tally.progress.bytes_in, tally.progress.bytes_out, {}};
    if (octree) {
        result.octree_note = octree->write(octree_file(tmp.path), content_key(layout), finite);
        const FiniteRange r = octree->range();
        if (r.any) tally.range.merge(r.min), tally.range.merge(r.max);
    }
    if (options.before_commit) options.before_commit(layout, tmp.path);
    check_stop();
    layout.bytes = tally.level0_bytes;
    commit(layout, tally.range, tmp, out, where);
    result.layout = layout;
    return result;
}

}  // namespace isowall::store
