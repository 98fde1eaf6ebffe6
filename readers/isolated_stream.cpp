#include "readers/isolated_stream.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <stdexcept>

#include "core/error.h"
#include "readers/child_process.h"
#include "wire/wire.h"

namespace isowall::formats {
namespace {

constexpr std::uint8_t kPlanesVersion = 1;
constexpr std::size_t kChildSlabBytes = std::size_t{16} << 20;  // what the child decodes at once

// The child's whole life: open the stack, write the description and every plane, and leave.
[[noreturn]] void child(const std::string& where, const std::function<PlaneStack()>& open,
                        int data_fd, int error_fd) {
    run_child(error_fd, [&]() -> std::string {
        const std::unique_ptr<PlaneSource> src = stream_planes(open(), where);
        MessageWriter w(kPlanesVersion);
        put_shape(w, {src->dims(), src->type(), src->spacing()});
        const std::vector<std::byte> header = w.take();
        const std::uint64_t length = header.size();
        bool ok =
            write_all(data_fd, &length, 8) && write_all(data_fd, header.data(), header.size());
        const int depth = src->dims().z;
        const std::size_t per_plane = std::max<std::size_t>(src->plane_bytes(), 1);
        const int step =
            int(std::clamp<std::size_t>(kChildSlabBytes / per_plane, 1, std::size_t(depth)));
        for (int z = 0; ok && z < depth; z += step) {
            const std::span<const std::byte> planes = src->planes(z, std::min(z + step, depth));
            ok = write_all(data_fd, planes.data(), planes.size());
        }
        return ok ? std::string()
                  : std::string("cannot hand the planes over: ") + std::strerror(errno);
    });
}

// The parent's end of a child: its pipes, and its end (reaped, or killed when dropped early).
class Child {
  public:
    Child(pid_t pid, int data, int errors, std::string where, std::string decoder,
          std::chrono::milliseconds quiet)
        : pid_(pid),
          data_(data),
          errors_(errors),
          where_(std::move(where)),
          decoder_(std::move(decoder)),
          quiet_(quiet) {}
    ~Child() {
        if (reaped_) return;
        ::kill(pid_, SIGKILL);
        wait_for(pid_);
    }
    Child(const Child&) = delete;
    Child& operator=(const Child&) = delete;

    // Exactly `n` bytes from the child, or the error its end means.
    void read(std::byte* to, std::size_t n) {
        while (n > 0) {
            pollfd p{data_.get(), POLLIN, 0};
            const int r = ::poll(&p, 1, int(std::min<long long>(quiet_.count(), 1 << 30)));
            if (r < 0 && errno == EINTR) continue;
            if (r == 0) {
                ::kill(pid_, SIGKILL);
                throw InputError(where_, "data",
                                 decoder_ + " sent nothing for " +
                                     std::to_string(quiet_.count() / 1000) + " s: it was ended");
            }
            const ssize_t got = ::read(data_.get(), to, n);
            if (got < 0 && errno == EINTR) continue;
            if (got <= 0) end(true);
            to += got;
            n -= std::size_t(got);
        }
    }

    // Ends the child now (the planes are dropped before their end); the destructor reaps it.
    void kill() {
        if (!reaped_) ::kill(pid_, SIGKILL);
    }

    // Waits for the child to leave; `early`: the planes stopped short of the last.
    void end(bool early) {
        std::string message;
        read_until_closed(errors_.get(), std::chrono::steady_clock::now() + quiet_, message);
        const int status = wait_for(pid_);
        reaped_ = true;
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
            child_failed(where_, decoder_, status, message);
        if (early) throw std::runtime_error(where_ + ": the reader's planes are cut short");
    }

  private:
    pid_t pid_;
    Fd data_, errors_;
    std::string where_, decoder_;
    std::chrono::milliseconds quiet_;
    std::atomic<bool> reaped_{false};
};

}  // namespace

std::unique_ptr<PlaneSource> stream_isolated(const std::string& where, const std::string& decoder,
                                             const std::function<PlaneStack()>& open,
                                             std::chrono::milliseconds quiet) {
    Pipe data = make_pipe(where), errors = make_pipe(where);
    const pid_t pid = fork_reader(where);
    if (pid == 0) {
        data.read.reset();
        errors.read.reset();
        child(where, open, data.write.get(), errors.write.get());
    }
    data.write.reset();
    errors.write.reset();
    auto c = std::make_shared<Child>(pid, data.read.release(), errors.read.release(), where,
                                     decoder, quiet);
    std::uint64_t length = 0;
    c->read(reinterpret_cast<std::byte*>(&length), 8);
    if (length > 4096) throw std::runtime_error(where + ": the reader's description is malformed");
    std::vector<std::byte> header(length);
    c->read(header.data(), header.size());
    MessageReader r(header, kPlanesVersion, "planes from the reader");
    const auto [dims, type, spacing] = get_shape(r);
    r.finish();
    if (glm::any(glm::lessThan(dims, glm::ivec3(1)))) r.fail("dims not positive");
    const std::size_t plane = std::size_t(dims.x) * dims.y * voxel_size(type);
    auto planes = std::make_unique<DecodedPlanes>(
        dims, type, spacing, where, [c, plane, depth = dims.z](int z0, int z1, std::byte* to) {
            c->read(to, plane * std::size_t(z1 - z0));
            if (z1 == depth) c->end(false);
        });
    // Dropped early (an import that failed elsewhere), the planes end the child, so that a read
    // ahead waiting on it returns at once rather than when the child writes or goes quiet.
    planes->set_cancel([c] { c->kill(); });
    return planes;
}

}  // namespace isowall::formats
