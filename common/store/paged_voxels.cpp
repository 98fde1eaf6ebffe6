#include "common/store/paged_voxels.h"

#include <fcntl.h>
#include <linux/userfaultfd.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <deque>
#include <list>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "common/core/error.h"

namespace isowall::store {

namespace {

std::string errno_text(const char* call) {
    return std::string(call) + ": " + std::strerror(errno);
}

// The pager's thread cannot throw into the thread stopped in a fault: one line, then exit.
[[noreturn]] void die(const std::string& what) {
    const std::string line = "isowall: error: " + clip(what, 800) + "\n";
    [[maybe_unused]] const ssize_t n = ::write(2, line.data(), line.size());
    ::_exit(1);
}

}  // namespace

struct PagedVoxels::State {
    // Chunks decompressed, most recently used first; a span needs one or two of them.
    struct Chunk {
        int cy = 0, cz = 0;
        std::vector<std::byte> bytes;
    };
    std::list<Chunk> chunks;
    std::uint64_t chunk_bytes = 0, chunk_budget = 0;
    std::vector<std::uint8_t> resident;  // per span: 1 while in memory
    std::vector<std::uint8_t> seen;      // per span: filled at least once
    std::deque<std::size_t> fifo;        // resident spans, oldest first
    std::uint64_t span_bytes_resident = 0;
    std::vector<std::byte> buffer;  // one span, filled then copied in
    mutable std::mutex mu;          // guards stats against readers of stats()
    PagingStats stats;
    std::thread thread;
};

std::uint64_t PagedVoxels::min_cap(const StoreLayout& l) {
    std::size_t biggest = l.chunk_bytes(0, 0);
    return 8 * biggest + 8 * kSpanBytes;
}

PagedVoxels::PagedVoxels(std::shared_ptr<const StoreReader> reader, std::uint64_t cap_bytes)
    : reader_(std::move(reader)), cap_(cap_bytes), state_(std::make_unique<State>()) {
    const StoreLayout& l = reader_->layout();
    if (cap_ < min_cap(l))
        throw InputError("--memory-limit", "value",
                         "at least " + std::to_string((min_cap(l) + (1 << 20) - 1) >> 20) +
                             "M for " + reader_->path().string() + " (eight chunks and spans)");
    voxel_bytes_ =
        static_cast<std::size_t>(l.dims.z) * static_cast<std::size_t>(l.dims.y) * l.row_bytes();
    map_bytes_ = (voxel_bytes_ + kSpanBytes - 1) / kSpanBytes * kSpanBytes;

    // UFFD_USER_MODE_ONLY lets a user without CAP_SYS_PTRACE page (kernels from 5.11); the voxels
    // are only ever read from user space.
    long fd = ::syscall(SYS_userfaultfd, O_CLOEXEC | O_NONBLOCK | UFFD_USER_MODE_ONLY);
    if (fd < 0 && errno == EINVAL) fd = ::syscall(SYS_userfaultfd, O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) throw std::runtime_error(errno_text("userfaultfd"));
    uffd_ = static_cast<int>(fd);
    auto fail = [&](const std::string& why) {
        if (base_) ::munmap(base_, map_bytes_);
        ::close(uffd_);
        if (stop_fd_ >= 0) ::close(stop_fd_);
        throw std::runtime_error(why);
    };
    uffdio_api api{};
    api.api = UFFD_API;
    if (::ioctl(uffd_, UFFDIO_API, &api) != 0) fail(errno_text("UFFDIO_API"));
    void* p = ::mmap(nullptr, map_bytes_, PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (p == MAP_FAILED) fail(errno_text("mmap"));
    base_ = static_cast<std::byte*>(p);
    uffdio_register reg{};
    reg.range.start = reinterpret_cast<std::uintptr_t>(base_);
    reg.range.len = map_bytes_;
    reg.mode = UFFDIO_REGISTER_MODE_MISSING;
    if (::ioctl(uffd_, UFFDIO_REGISTER, &reg) != 0) fail(errno_text("UFFDIO_REGISTER"));
    stop_fd_ = ::eventfd(0, EFD_CLOEXEC);
    if (stop_fd_ < 0) fail(errno_text("eventfd"));

    State& s = *state_;
    const std::size_t spans = map_bytes_ / kSpanBytes;
    s.resident.assign(spans, 0);
    s.seen.assign(spans, 0);
    s.buffer.resize(kSpanBytes);
    // The chunk cache only saves decompressing a chunk again for its neighbouring spans, so a
    // few dozen MiB serve; the rest of the cap is for the voxels themselves.
    s.chunk_budget = std::max<std::uint64_t>(std::min<std::uint64_t>(cap_ / 8, 32 << 20),
                                             4 * l.chunk_bytes(0, 0));
    s.thread = std::thread([this] { serve(); });
}

PagedVoxels::~PagedVoxels() {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(stop_fd_, &one, sizeof(one));
    if (state_->thread.joinable()) state_->thread.join();
    ::munmap(base_, map_bytes_);
    ::close(uffd_);
    ::close(stop_fd_);
}

PagingStats PagedVoxels::stats() const {
    std::lock_guard lock(state_->mu);
    return state_->stats;
}

void PagedVoxels::serve() {
    State& s = *state_;
    const StoreLayout& l = reader_->layout();
    const std::size_t row = l.row_bytes();
    const std::size_t spans = s.resident.size();

    // The chunk (cy, cz), from the cache or from disk (then cached, the least recently used
    // dropped past the budget).
    auto chunk = [&](int cy, int cz) -> const std::vector<std::byte>& {
        for (auto it = s.chunks.begin(); it != s.chunks.end(); ++it)
            if (it->cy == cy && it->cz == cz) {
                s.chunks.splice(s.chunks.begin(), s.chunks, it);
                std::lock_guard lock(s.mu);
                s.stats.chunk_hits += 1;
                return s.chunks.front().bytes;
            }
        State::Chunk c{cy, cz, std::vector<std::byte>(l.chunk_bytes(cy, cz))};
        std::size_t read = 0;
        try {
            read = reader_->read_chunk(cy, cz, c.bytes);
        } catch (const std::exception& e) {
            die(e.what());
        }
        s.chunk_bytes += c.bytes.size();
        s.chunks.push_front(std::move(c));
        while (s.chunk_bytes > s.chunk_budget && s.chunks.size() > 2) {
            s.chunk_bytes -= s.chunks.back().bytes.size();
            s.chunks.pop_back();
        }
        std::lock_guard lock(s.mu);
        s.stats.chunks_read += 1;
        s.stats.bytes_read += read;
        return s.chunks.front().bytes;
    };

    // Span `i`'s bytes into the buffer: each row it crosses, from the chunk that holds the row.
    auto fill = [&](std::size_t i) {
        const std::size_t begin = i * kSpanBytes;
        const std::size_t end = std::min(begin + kSpanBytes, voxel_bytes_);
        std::fill(s.buffer.begin(), s.buffer.end(), std::byte{0});
        for (std::size_t at = begin; at < end;) {
            const std::size_t r = at / row;  // row index = z * dims.y + y
            const int y = static_cast<int>(r % static_cast<std::size_t>(l.dims.y));
            const int z = static_cast<int>(r / static_cast<std::size_t>(l.dims.y));
            const int cy = y / l.chunk_rows, cz = z / l.chunk_slices;
            const glm::ivec2 e = l.chunk_extent(cy, cz);
            const std::vector<std::byte>& c = chunk(cy, cz);
            // This row and the rows after it in the same chunk slice are contiguous there too.
            const std::size_t in_row = at - r * row;
            const std::size_t rows_left = static_cast<std::size_t>(cy * l.chunk_rows + e.x - y);
            const std::size_t run = std::min(rows_left * row - in_row, end - at);
            const std::size_t src =
                (static_cast<std::size_t>(z - cz * l.chunk_slices) * static_cast<std::size_t>(e.x) +
                 static_cast<std::size_t>(y - cy * l.chunk_rows)) *
                    row +
                in_row;
            std::memcpy(s.buffer.data() + (at - begin), c.data() + src, run);
            at += run;
        }
    };

    auto evict_to_cap = [&](std::size_t keep) {
        while (s.span_bytes_resident + s.chunk_bytes > cap_ && !s.fifo.empty()) {
            const std::size_t old = s.fifo.front();
            if (old == keep && s.fifo.size() == 1) break;
            s.fifo.pop_front();
            if (old == keep) {
                s.fifo.push_back(old);
                continue;
            }
            ::madvise(base_ + old * kSpanBytes, kSpanBytes, MADV_DONTNEED);
            s.resident[old] = 0;
            s.span_bytes_resident -= kSpanBytes;
            std::lock_guard lock(s.mu);
            s.stats.evictions += 1;
        }
    };

    pollfd fds[2] = {{uffd_, POLLIN, 0}, {stop_fd_, POLLIN, 0}};
    for (;;) {
        if (::poll(fds, 2, -1) < 0) {
            if (errno == EINTR) continue;
            die("the volume's pager: " + errno_text("poll"));
        }
        if (fds[1].revents) return;
        uffd_msg msg{};
        const ssize_t n = ::read(uffd_, &msg, sizeof(msg));
        if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
        if (n != sizeof(msg)) die("the volume's pager: " + errno_text("read"));
        if (msg.event != UFFD_EVENT_PAGEFAULT) continue;
        const auto addr = static_cast<std::uintptr_t>(msg.arg.pagefault.address);
        const std::size_t i = (addr - reinterpret_cast<std::uintptr_t>(base_)) / kSpanBytes;
        if (i >= spans) die("the volume's pager: a fault outside the volume");
        const auto t0 = std::chrono::steady_clock::now();
        if (s.resident[i]) {
            // A second reader of a span filled since its fault was queued: wake it.
            uffdio_range wake{reinterpret_cast<std::uintptr_t>(base_ + i * kSpanBytes), kSpanBytes};
            ::ioctl(uffd_, UFFDIO_WAKE, &wake);
            continue;
        }
        fill(i);
        uffdio_copy copy{};
        copy.dst = reinterpret_cast<std::uintptr_t>(base_ + i * kSpanBytes);
        copy.src = reinterpret_cast<std::uintptr_t>(s.buffer.data());
        copy.len = kSpanBytes;
        while (::ioctl(uffd_, UFFDIO_COPY, &copy) != 0) {
            if (errno == EAGAIN && copy.copy > 0) {
                // Part copied: go on from there.
                copy.dst += static_cast<std::uint64_t>(copy.copy);
                copy.src += static_cast<std::uint64_t>(copy.copy);
                copy.len -= static_cast<std::uint64_t>(copy.copy);
                copy.copy = 0;
                continue;
            }
            if (errno == EAGAIN) continue;
            if (errno ==
                EEXIST) {  // a page of it is there already (cannot happen: spans move whole)
                uffdio_range wake{copy.dst, copy.len};
                ::ioctl(uffd_, UFFDIO_WAKE, &wake);
                break;
            }
            die("the volume's pager: " + errno_text("UFFDIO_COPY"));
        }
        s.resident[i] = 1;
        s.fifo.push_back(i);
        s.span_bytes_resident += kSpanBytes;
        evict_to_cap(i);
        const double dt =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::lock_guard lock(s.mu);
        s.stats.faults += 1;
        if (s.seen[i]) s.stats.refaults += 1;
        s.seen[i] = 1;
        s.stats.fill_s += dt;
        s.stats.resident_bytes = s.span_bytes_resident + s.chunk_bytes;
        s.stats.peak_bytes = std::max(s.stats.peak_bytes, s.stats.resident_bytes);
    }
}

std::string paging_line(const PagingStats& s, std::uint64_t cap) {
    const double mib = 1024.0 * 1024.0;
    const std::uint64_t needs = s.chunks_read + s.chunk_hits;
    char line[320];
    std::snprintf(line, sizeof line,
                  "bricks: %llu read (%.1f MiB from disk), chunk cache hits %.0f%%; spans: %llu "
                  "filled, %llu refilled, %llu dropped; peak %.1f MiB of the %.0f MiB limit; "
                  "%.3f s filling",
                  static_cast<unsigned long long>(s.chunks_read), double(s.bytes_read) / mib,
                  needs ? 100.0 * double(s.chunk_hits) / double(needs) : 0.0,
                  static_cast<unsigned long long>(s.faults),
                  static_cast<unsigned long long>(s.refaults),
                  static_cast<unsigned long long>(s.evictions), double(s.peak_bytes) / mib,
                  double(cap) / mib, s.fill_s);
    return line;
}

}  // namespace isowall::store
