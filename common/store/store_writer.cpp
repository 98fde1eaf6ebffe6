#include "common/store/store_writer.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include <zstd.h>

#include "common/core/error.h"

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

struct TempDir {
    fs::path path;
    bool keep = false;
    ~TempDir() {
        if (keep) return;
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

}  // namespace

fs::path temporary_for(const fs::path& out) {
    const fs::path abs = fs::absolute(out).lexically_normal();
    const fs::path name = abs.has_filename() ? abs.filename() : abs.parent_path().filename();
    const fs::path dir = abs.has_filename() ? abs.parent_path() : abs.parent_path().parent_path();
    std::string hidden(1, '.');  // built in steps: GCC 12 warns falsely on "." + s + "..."
    hidden.append(name.string()).append(".importing");
    return dir / hidden;
}

ImportResult write_store(const Volume& volume, const fs::path& out, const ImportOptions& options) {
    const std::string where = out.string();
    std::error_code ec;
    if (fs::exists(out, ec) && !options.replace)
        throw InputError(where, "--out", "exists; give --force to replace it");
    if (fs::exists(out, ec) && !is_store(out))
        throw InputError(where, "--out", "exists and is not a store; it is left alone");

    StoreLayout layout = layout_for(volume.dims(), volume.type(), volume.spacing());
    layout.source = volume.source();
    layout.zstd_level = options.zstd_level;
    const glm::ivec2 grid = layout.chunk_grid();

    TempDir tmp{temporary_for(out)};
    fs::remove_all(tmp.path, ec);  // what a stopped run left
    for (int cz = 0; cz < grid.y; ++cz)
        for (int cy = 0; cy < grid.x; ++cy) {
            fs::create_directories(tmp.path / fs::path(chunk_key(cy, cz)).parent_path(), ec);
            if (ec) throw InputError(where, "--out", "cannot make its folders: " + ec.message());
        }

    const std::span<const std::byte> all = volume.bytes();
    const std::size_t slice_bytes = layout.row_bytes() * static_cast<std::size_t>(layout.dims.y);
    const int threads = std::max(1, std::min(options.threads, grid.x));
    ImportProgress progress;
    progress.chunks_total = layout.chunk_count();
    Range range;
    std::mutex mu;
    std::string failure;

    for (int cz = 0; cz < grid.y; ++cz) {
        // Chunk rows of this slab, split over the threads; each has its own buffers and context.
        auto work = [&](int first, int last) {
            ZSTD_CCtx* cctx = ZSTD_createCCtx();
            ZSTD_CCtx_setParameter(cctx, ZSTD_c_compressionLevel, layout.zstd_level);
            ZSTD_CCtx_setParameter(cctx, ZSTD_c_checksumFlag, 1);
            std::vector<std::byte> raw, packed;
            try {
                for (int cy = first; cy < last; ++cy) {
                    const glm::ivec2 e = layout.chunk_extent(cy, cz);
                    const std::size_t block = layout.row_bytes() * static_cast<std::size_t>(e.x);
                    raw.resize(layout.chunk_bytes(cy, cz));
                    for (int z = 0; z < e.y; ++z) {
                        const std::size_t src =
                            static_cast<std::size_t>(cz * layout.chunk_slices + z) * slice_bytes +
                            static_cast<std::size_t>(cy * layout.chunk_rows) * layout.row_bytes();
                        std::memcpy(raw.data() + static_cast<std::size_t>(z) * block,
                                    all.data() + src, block);
                    }
                    packed.resize(ZSTD_compressBound(raw.size()));
                    const std::size_t n =
                        ZSTD_compress2(cctx, packed.data(), packed.size(), raw.data(), raw.size());
                    if (ZSTD_isError(n))
                        throw InputError(where, chunk_key(cy, cz),
                                         std::string("zstd: ") + ZSTD_getErrorName(n));
                    write_file(tmp.path / chunk_key(cy, cz), std::span(packed.data(), n), where,
                               chunk_key(cy, cz));
                    const Range r = range_of(raw, layout.type);
                    std::lock_guard lock(mu);
                    range.merge(r.min);
                    range.merge(r.max);
                    progress.chunks_done += 1;
                    progress.bytes_in += raw.size();
                    progress.bytes_out += n;
                }
            } catch (const std::exception& ex) {
                std::lock_guard lock(mu);
                if (failure.empty()) failure = ex.what();
            }
            ZSTD_freeCCtx(cctx);
        };
        std::vector<std::thread> pool;
        for (int t = 1; t < threads; ++t)
            pool.emplace_back(work, grid.x * t / threads, grid.x * (t + 1) / threads);
        work(0, grid.x / threads);
        for (auto& th : pool) th.join();
        if (!failure.empty()) throw InputError::relayed(failure);
        if (volume.mapped()) {
            const std::size_t z0 = static_cast<std::size_t>(cz) * layout.chunk_slices;
            const std::size_t z1 =
                std::min<std::size_t>(z0 + layout.chunk_slices, std::size_t(layout.dims.z));
            release_source_pages(all.data() + z0 * slice_bytes, all.data() + z1 * slice_bytes);
        }
        if (options.progress) options.progress(progress);
    }
    if (range.min > range.max) range.min = range.max = 0;  // no finite voxel
    layout.value_min = range.min;
    layout.value_max = range.max;
    write_text(tmp.path / ".zgroup", zgroup_json(), where, ".zgroup");
    write_text(tmp.path / "0" / ".zarray", zarray_json(layout), where, "0/.zarray");
    write_text(tmp.path / ".zattrs", zattrs_json(layout), where, ".zattrs");

    // Into place: an old store moves aside first and goes only once the new one is in.
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
    return {layout, progress.bytes_in, progress.bytes_out};
}

}  // namespace isowall::store
