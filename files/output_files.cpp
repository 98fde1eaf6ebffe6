#include "files/output_files.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include "core/error.h"

namespace isowall {
namespace {

// The registry of live temporaries, read by the signal handler: fixed storage, and a slot's path
// is written before the slot is marked live, so the handler only ever reads complete paths.
enum SlotState : int { kFree = 0, kFilling = 1, kLive = 2 };
struct Slot {
    std::atomic<int> state{kFree};
    char path[4096];
};
Slot g_slots[kMaxLiveTemporaries];

int register_temporary(const std::filesystem::path& p) {
    const std::string& s = p.native();
    if (s.size() >= sizeof(Slot::path))
        throw std::runtime_error(clip_source(s) + ": path too long for a temporary file");
    for (std::size_t i = 0; i < kMaxLiveTemporaries; ++i) {
        int expected = kFree;
        if (!g_slots[i].state.compare_exchange_strong(expected, kFilling)) continue;
        std::memcpy(g_slots[i].path, s.c_str(), s.size() + 1);
        g_slots[i].state.store(kLive, std::memory_order_release);
        return static_cast<int>(i);
    }
    throw std::runtime_error("more than " + std::to_string(kMaxLiveTemporaries) +
                             " output files at once");
}

void unregister_temporary(int slot) {
    if (slot >= 0) g_slots[slot].state.store(kFree, std::memory_order_release);
}

extern "C" void remove_temporaries_and_die(int sig) {
    for (Slot& s : g_slots)
        if (s.state.load(std::memory_order_acquire) == kLive) ::unlink(s.path);
    // SA_RESETHAND has restored the default action; the signal is blocked until we return.
    ::raise(sig);
}

std::filesystem::path temporary_beside(const std::filesystem::path& target) {
    static std::atomic<unsigned> counter{0};
    std::string name(".");
    name += target.stem().string();
    name += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    name += target.extension().string();
    return target.parent_path() / name;
}

// Whether a file can be created in `dir`, without leaving one: an unnamed O_TMPFILE, or where the
// file system has none, a named probe removed at once (and registered meanwhile, like any
// temporary). Permission bits alone would say yes to root in /proc or on a read-only mount.
std::string folder_write_problem(const std::filesystem::path& dir) {
    int fd = ::open(dir.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0600);
    int err = errno;
    if (fd < 0 && (err == EOPNOTSUPP || err == EISDIR || err == EINVAL)) {
        const std::filesystem::path probe = temporary_beside(dir / "isowall-probe");
        const int slot = register_temporary(probe);
        fd = ::open(probe.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0600);
        err = errno;
        if (fd >= 0) ::unlink(probe.c_str());
        unregister_temporary(slot);
    }
    if (fd < 0)
        return "cannot write in folder " + clip_source(dir.string()) + ": " + std::strerror(err);
    ::close(fd);
    return {};
}

}  // namespace

std::string output_problem(const std::filesystem::path& target) {
    namespace fs = std::filesystem;
    if (target.empty()) return "expected a file name, got \"\"";
    std::error_code ec;
    const fs::file_status st = fs::status(target, ec);
    if (fs::is_directory(st)) return "is a folder; expected a file name";
    if (fs::exists(st) && !fs::is_regular_file(st))
        return "is not a regular file (a device, pipe or socket); expected a file name";
    const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    const fs::file_status dst = fs::status(dir, ec);
    if (!fs::exists(dst)) return "folder " + clip_source(dir.string()) + " does not exist";
    if (!fs::is_directory(dst)) return clip_source(dir.string()) + " is not a folder";
    return folder_write_problem(dir);
}

void check_output(const std::filesystem::path& target, const std::string& option) {
    const std::string problem = output_problem(target);
    if (problem.empty()) return;
    if (target.empty()) throw InputError(option, "value", problem);
    throw InputError(target.string(), option, problem);
}

OutputFiles::~OutputFiles() {
    for (const Staged& s : staged_) {
        ::unlink(s.temporary.c_str());
        unregister_temporary(s.slot);
    }
}

std::filesystem::path OutputFiles::stage(const std::filesystem::path& target) {
    Staged s;
    s.target = target;
    s.temporary = temporary_beside(target);
    s.slot = register_temporary(s.temporary);
    staged_.push_back(s);
    return s.temporary;
}

void OutputFiles::commit() {
    for (std::size_t i = 0; i < staged_.size(); ++i) {
        std::error_code ec;
        std::filesystem::rename(staged_[i].temporary, staged_[i].target, ec);
        if (!ec) continue;
        // Undo this batch: the targets renamed so far go, and so do the temporaries left.
        for (std::size_t k = 0; k < staged_.size(); ++k) {
            ::unlink((k < i ? staged_[k].target : staged_[k].temporary).c_str());
            unregister_temporary(staged_[k].slot);
        }
        const std::string target = clip_source(staged_[i].target.string());
        staged_.clear();
        throw std::runtime_error(target + ": cannot write: " + ec.message());
    }
    for (const Staged& s : staged_) unregister_temporary(s.slot);
    staged_.clear();
}

void write_bytes_checked(const std::filesystem::path& file,
                         std::initializer_list<std::span<const std::byte>> parts,
                         const std::string& name) {
    const auto fail = [&](const char* what) {
        throw std::runtime_error(clip_source(name) + ": cannot " + what + ": " +
                                 std::strerror(errno));
    };
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) fail("create");
    for (std::span<const std::byte> bytes : parts) {
        std::size_t done = 0;
        while (done < bytes.size()) {
            const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                if (n == 0) errno = ENOSPC;  // a write that takes nothing: the device is full
                const int saved = errno;
                ::close(fd);
                errno = saved;
                fail("write");
            }
            done += static_cast<std::size_t>(n);
        }
    }
    if (::fsync(fd) != 0 && errno != EINVAL) {  // EINVAL: a file system without fsync
        const int saved = errno;
        ::close(fd);
        errno = saved;
        fail("write");
    }
    if (::close(fd) != 0) fail("write");
}

void write_output(const std::filesystem::path& target,
                  const std::function<void(const std::filesystem::path& temporary)>& write) {
    OutputFiles out;
    write(out.stage(target));
    out.commit();
}

void install_output_cleanup() {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
        struct sigaction old {};
        if (::sigaction(sig, nullptr, &old) != 0 || old.sa_handler != SIG_DFL) continue;
        struct sigaction sa {};
        sa.sa_handler = remove_temporaries_and_die;
        sigemptyset(&sa.sa_mask);
        sa.sa_flags = SA_RESETHAND;
        ::sigaction(sig, &sa, nullptr);
    }
}

std::size_t live_temporaries() {
    std::size_t n = 0;
    for (const Slot& s : g_slots) n += s.state.load() == kLive ? 1 : 0;
    return n;
}

}  // namespace isowall
