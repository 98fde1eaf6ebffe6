#include "store/paged_voxels.h"

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
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <deque>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/fatal.h"

namespace isowall::store {

namespace {

std::string errno_text(const char* call) {
    return std::string(call) + ": " + std::strerror(errno);
}

// The pager's thread cannot throw into the thread stopped in a fault (core/fatal.h).
[[noreturn]] void die(const std::string& what) {
    end_with_error(what);
}

double thread_cpu_s() {
    timespec t{};
    ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

long open_userfaultfd() {
    // UFFD_USER_MODE_ONLY lets a user without CAP_SYS_PTRACE page (kernels from 5.11); the voxels
    // are only ever read from user space.
    long fd = ::syscall(SYS_userfaultfd, O_CLOEXEC | O_NONBLOCK | UFFD_USER_MODE_ONLY);
    if (fd < 0 && errno == EINVAL) fd = ::syscall(SYS_userfaultfd, O_CLOEXEC | O_NONBLOCK);
    return fd;
}

}  // namespace

// Two pager threads read faults from one userfaultfd: while one decompresses a brick, the other
// serves the next fault (the CT head's 1,508 bricks took 0.51 s of reading on one). Each brick
// is read by one of them: the first to claim it (kLoading); a fault on a brick being loaded is
// dropped, since the copy that installs it wakes every thread waiting on it.
struct PagedVoxels::State {
    static constexpr std::uint8_t kAbsent = 0, kLoading = 1, kResident = 2;
    static constexpr int kThreads = 2;
    std::mutex mu;                     // guards everything below but the buffers
    std::vector<std::uint8_t> state;   // per brick: kAbsent, kLoading, kResident
    std::vector<std::uint8_t> seen;    // per brick: read at least once
    std::deque<std::size_t> fifo;      // resident bricks, oldest first
    std::vector<std::uint8_t> hinted;  // per brick: queued for read-ahead once
    std::vector<std::uint8_t> wanted;  // per brick: on the surface (want()); empty: none known
    std::vector<std::size_t> ahead;    // bricks to read ahead, newest last
    std::condition_variable ahead_cv;
    bool stopping = false;
    std::thread ahead_thread;
    std::uint64_t resident_bytes = 0;
    PagingStats stats;
    std::vector<std::thread> threads;
};

std::uint64_t PagedVoxels::min_cap(const StoreLayout& l) {
    return 16 * static_cast<std::uint64_t>(l.brick_bytes());
}

PagedVoxels::PagedVoxels(std::shared_ptr<const StoreReader> reader, std::uint64_t cap_bytes,
                         bool read_ahead)
    : reader_(std::move(reader)), cap_(cap_bytes), state_(std::make_unique<State>()) {
    const StoreLayout& l = reader_->layout();
    if (cap_ < min_cap(l))
        throw InputError("--memory-limit", "value",
                         "at least " + std::to_string((min_cap(l) + (1 << 20) - 1) >> 20) +
                             "M for " + reader_->path().string() + " (sixteen of its bricks)");
    brick_bytes_ = l.brick_bytes();
    map_bytes_ = l.chunk_count() * brick_bytes_;

    const long fd = open_userfaultfd();
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
    s.state.assign(l.chunk_count(), State::kAbsent);
    s.seen.assign(l.chunk_count(), 0);
    // Hinting 0 marks every brick as queued already: no read-ahead.
    s.hinted.assign(l.chunk_count(), read_ahead ? 0 : 1);
    for (int t = 0; t < State::kThreads; ++t) s.threads.emplace_back([this] { serve(); });
    if (read_ahead) s.ahead_thread = std::thread([this] { this->read_ahead(); });
}

PagedVoxels::~PagedVoxels() {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(stop_fd_, &one, sizeof(one));
    for (auto& t : state_->threads) t.join();
    {
        std::lock_guard lock(state_->mu);
        state_->stopping = true;
    }
    state_->ahead_cv.notify_all();
    if (state_->ahead_thread.joinable()) state_->ahead_thread.join();
    ::munmap(base_, map_bytes_);
    ::close(uffd_);
    ::close(stop_fd_);
}

void PagedVoxels::want(std::vector<std::uint8_t> bricks) const {
    std::lock_guard lock(state_->mu);
    if (bricks.size() == state_->state.size()) state_->wanted = std::move(bricks);
}

PagingStats PagedVoxels::stats() const {
    std::lock_guard lock(state_->mu);
    return state_->stats;
}

// The stop event stays readable once written, so every pager thread sees it.

// Drops the oldest resident bricks (never `keep`, the one just read) until under the cap. Called
// with the state's lock held.
void PagedVoxels::drop_to_cap(std::size_t keep) {
    State& s = *state_;
    while (s.resident_bytes > cap_ && s.fifo.size() > 1) {
        const std::size_t old = s.fifo.front();
        s.fifo.pop_front();
        if (old == keep) {
            s.fifo.push_back(old);
            continue;
        }
        ::madvise(base_ + old * brick_bytes_, brick_bytes_, MADV_DONTNEED);
        s.state[old] = State::kAbsent;
        s.resident_bytes -= brick_bytes_;
        s.stats.evictions += 1;
    }
}

// Queues the face neighbours of brick `i` that were never read nor queued. Called with the
// state's lock held. The queue keeps the newest 1,024: hints that old no longer lead a front.
void PagedVoxels::hint_neighbours(std::size_t i) {
    State& s = *state_;
    const StoreLayout& l = reader_->layout();
    const glm::ivec3 g = l.grid(), b = l.brick_at(i);
    static constexpr int kSteps[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                         {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    bool any = false;
    for (const auto& d : kSteps) {
        const glm::ivec3 n = b + glm::ivec3(d[0], d[1], d[2]);
        if (n.x < 0 || n.y < 0 || n.z < 0 || n.x >= g.x || n.y >= g.y || n.z >= g.z) continue;
        const std::size_t j = l.brick_index(n);
        if (s.hinted[j] || s.seen[j] || s.wanted.size() <= j || !s.wanted[j]) continue;
        s.hinted[j] = 1;
        s.ahead.push_back(j);
        any = true;
    }
    constexpr std::size_t kMost = 1024;
    if (s.ahead.size() > kMost) s.ahead.erase(s.ahead.begin(), s.ahead.end() - kMost);
    if (any) s.ahead_cv.notify_one();
}

void PagedVoxels::read_ahead() {
    State& s = *state_;
    const StoreLayout& l = reader_->layout();
    std::unique_lock lock(s.mu);
    for (;;) {
        s.ahead_cv.wait(lock, [&] { return s.stopping || !s.ahead.empty(); });
        if (s.stopping) return;
        const std::size_t j = s.ahead.back();  // the newest: nearest the work going on now
        s.ahead.pop_back();
        if (s.seen[j]) continue;  // touched meanwhile
        s.stats.hinted += 1;
        lock.unlock();
        reader_->prefetch(l.brick_at(j));
        lock.lock();
    }
}

// Copies `buffer` into brick `i` (waking the threads stopped on it).
void PagedVoxels::install(std::size_t i, const std::vector<std::byte>& buffer) {
    uffdio_copy copy{};
    copy.dst = reinterpret_cast<std::uintptr_t>(base_ + i * brick_bytes_);
    copy.src = reinterpret_cast<std::uintptr_t>(buffer.data());
    copy.len = brick_bytes_;
    while (::ioctl(uffd_, UFFDIO_COPY, &copy) != 0) {
        if (errno == EAGAIN && copy.copy > 0) {  // part copied: go on from there
            copy.dst += static_cast<std::uint64_t>(copy.copy);
            copy.src += static_cast<std::uint64_t>(copy.copy);
            copy.len -= static_cast<std::uint64_t>(copy.copy);
            copy.copy = 0;
            continue;
        }
        if (errno == EAGAIN) continue;
        if (errno == EEXIST) {  // cannot happen (bricks come and go whole); wake whoever waits
            uffdio_range wake{copy.dst, copy.len};
            ::ioctl(uffd_, UFFDIO_WAKE, &wake);
            return;
        }
        die("the volume's pager: " + errno_text("UFFDIO_COPY"));
    }
}

void PagedVoxels::serve() {
    State& s = *state_;
    const StoreLayout& l = reader_->layout();
    const std::size_t bricks = s.state.size();
    std::vector<std::byte> buffer(brick_bytes_);  // one brick, decompressed then copied in
    pollfd fds[2] = {{uffd_, POLLIN, 0}, {stop_fd_, POLLIN, 0}};
    for (;;) {
        if (::poll(fds, 2, -1) < 0) {
            if (errno == EINTR) continue;
            die("the volume's pager: " + errno_text("poll"));
        }
        if (fds[1].revents) return;
        uffd_msg msg{};
        const ssize_t n = ::read(uffd_, &msg, sizeof(msg));
        if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;  // the other thread took it
        if (n != sizeof(msg)) die("the volume's pager: " + errno_text("read"));
        if (msg.event != UFFD_EVENT_PAGEFAULT) continue;
        const auto addr = static_cast<std::uintptr_t>(msg.arg.pagefault.address);
        const std::size_t i = (addr - reinterpret_cast<std::uintptr_t>(base_)) / brick_bytes_;
        if (i >= bricks) die("the volume's pager: a fault outside the volume");
        {
            std::lock_guard lock(s.mu);
            if (s.state[i] == State::kLoading) continue;  // its copy wakes this fault too
            if (s.state[i] == State::kResident) {
                // A fault queued before the brick came in: wake it.
                uffdio_range wake{reinterpret_cast<std::uintptr_t>(base_ + i * brick_bytes_),
                                  brick_bytes_};
                ::ioctl(uffd_, UFFDIO_WAKE, &wake);
                continue;
            }
            s.state[i] = State::kLoading;
            if (!s.seen[i]) hint_neighbours(i);
        }
        const auto t0 = std::chrono::steady_clock::now();
        const double cpu0 = thread_cpu_s();
        std::size_t read = 0;
        try {
            read = reader_->read_chunk(l.brick_at(i), buffer);
        } catch (const std::exception& e) {
            die(e.what());
        }
        install(i, buffer);
        const double dt =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::lock_guard lock(s.mu);
        s.state[i] = State::kResident;
        s.fifo.push_back(i);
        s.resident_bytes += brick_bytes_;
        drop_to_cap(i);
        s.stats.faults += 1;
        if (s.seen[i]) s.stats.refaults += 1;
        s.seen[i] = 1;
        s.stats.bytes_read += read;
        s.stats.fill_s += dt;
        s.stats.cpu_s += thread_cpu_s() - cpu0;
        s.stats.resident_bytes = s.resident_bytes;
        s.stats.peak_bytes = std::max(s.stats.peak_bytes, s.resident_bytes);
    }
}

std::string paging_unavailable() {
    const long fd = open_userfaultfd();
    if (fd < 0) return errno_text("userfaultfd");
    ::close(static_cast<int>(fd));
    return "";
}

std::string paging_line(const PagingStats& s, std::uint64_t cap) {
    const double mib = 1024.0 * 1024.0;
    char line[320];
    std::snprintf(line, sizeof line,
                  "bricks: %llu read (%.1f MiB from disk), %llu read again, %llu dropped; peak "
                  "%.1f MiB of the %.0f MiB limit; %.3f s reading; %llu chunks read ahead",
                  static_cast<unsigned long long>(s.faults), double(s.bytes_read) / mib,
                  static_cast<unsigned long long>(s.refaults),
                  static_cast<unsigned long long>(s.evictions), double(s.peak_bytes) / mib,
                  double(cap) / mib, s.fill_s, static_cast<unsigned long long>(s.hinted));
    return line;
}

}  // namespace isowall::store
