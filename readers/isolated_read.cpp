#include "readers/isolated_read.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <stdexcept>

#include "core/error.h"
#include "readers/child_process.h"
#include "wire/wire.h"

namespace isowall::formats {
namespace {

constexpr std::uint8_t kHeaderVersion = 1;
constexpr std::size_t kVoxelsAlign = 4096;  // the voxels start on a page of the memory file

using Clock = std::chrono::steady_clock;

// Where the voxels start in the memory file: after the header's length (8 bytes) and the header,
// on the next page.
std::size_t voxels_offset(std::size_t header_bytes) {
    return (8 + header_bytes + kVoxelsAlign - 1) / kVoxelsAlign * kVoxelsAlign;
}

// The child's whole life: read, write the volume (or the error's line) and leave.
[[noreturn]] void child(const std::function<Volume()>& read, int data_fd, int error_fd) {
    run_child(error_fd, [&]() -> std::string {
        const Volume v = read();
        const std::vector<std::byte> header = encode_volume_header(v);
        const std::uint64_t length = header.size();
        const std::vector<char> pad(voxels_offset(header.size()) - 8 - header.size(), 0);
        const std::span<const std::byte> voxels = v.bytes();
        if (write_all(data_fd, &length, 8) && write_all(data_fd, header.data(), header.size()) &&
            write_all(data_fd, pad.data(), pad.size()) &&
            write_all(data_fd, voxels.data(), voxels.size()))
            return {};
        return std::string("cannot hand the volume over: ") + std::strerror(errno);
    });
}

}  // namespace

void put_shape(MessageWriter& w, const VolumeShape& s) {
    w.put(s.dims.x);
    w.put(s.dims.y);
    w.put(s.dims.z);
    w.put(static_cast<std::uint8_t>(s.type));
    w.put(s.spacing);
}

VolumeShape get_shape(MessageReader& r) {
    VolumeShape s;
    s.dims.x = r.get<int>();
    s.dims.y = r.get<int>();
    s.dims.z = r.get<int>();
    const auto type = r.get<std::uint8_t>();
    if (type > static_cast<std::uint8_t>(VoxelType::f64)) r.fail("voxel type out of range");
    s.type = static_cast<VoxelType>(type);
    s.spacing = r.get_vec3();
    return s;
}

std::vector<std::byte> encode_volume_header(const Volume& v) {
    MessageWriter w(kHeaderVersion);
    put_shape(w, {v.dims(), v.type(), v.spacing()});
    w.put_string(v.source());
    w.put(static_cast<std::uint64_t>(v.files().size()));
    for (const auto& f : v.files()) w.put_string(f.string());
    const Orientation& o = v.orientation();
    for (int c = 0; c < 3; ++c) w.put(glm::vec3(o.axes[c]));
    w.put(o.origin);
    w.put(static_cast<std::uint8_t>(o.known));
    w.put(static_cast<std::uint64_t>(v.facts().size()));
    for (const VolumeFact& f : v.facts()) {
        w.put_string(f.name);
        w.put_string(f.value);
    }
    return w.take();
}

Volume decode_volume(std::span<const std::byte> header, MappedFile file, std::size_t offset) {
    MessageReader r(header, kHeaderVersion, "volume from the reader");
    const auto [dims, type, spacing] = get_shape(r);
    std::string source = r.get_string();
    std::vector<std::filesystem::path> files(r.get_count(8));
    for (auto& f : files) f = r.get_string();
    Orientation o;
    for (int c = 0; c < 3; ++c) o.axes[c] = r.get_vec3();
    o.origin = r.get_vec3();
    o.known = r.get_bool();
    std::vector<VolumeFact> facts(r.get_count(16));
    for (VolumeFact& f : facts) {
        f.name = r.get_string();
        f.value = r.get_string();
    }
    r.finish();
    if (glm::any(glm::lessThan(dims, glm::ivec3(1)))) r.fail("dims not positive");
    const std::size_t size = voxel_size(type);
    const std::size_t room = offset <= file.size() ? file.size() - offset : 0;
    if (std::size_t(dims.x) > room / size / std::size_t(dims.y) / std::size_t(dims.z))
        throw std::runtime_error("the reader's voxels are cut short");
    Volume v(dims, type, spacing, std::move(file), offset, std::move(source));
    v.set_files(std::move(files));
    v.set_orientation(o);
    for (VolumeFact& f : facts) v.add_fact(std::move(f.name), std::move(f.value));
    return v;
}

Volume read_isolated(const std::string& where, const std::string& decoder,
                     const std::function<Volume()>& read, std::chrono::milliseconds limit) {
    Fd data(::memfd_create("isowall-volume", MFD_CLOEXEC));
    if (data.get() < 0)
        throw std::runtime_error(
            where + ": cannot make a memory file for the reader: " + std::strerror(errno));
    Pipe errors = make_pipe(where);
    const pid_t pid = fork_reader(where);
    if (pid == 0) child(read, data.get(), errors.write.get());
    errors.write.reset();
    std::string message;
    if (!read_until_closed(errors.read.get(), Clock::now() + limit, message)) {
        ::kill(pid, SIGKILL);
        wait_for(pid);
        throw InputError(where, "data",
                         decoder + " did not finish within " +
                             std::to_string(limit.count() / 1000) + " s: it was ended");
    }
    const int status = wait_for(pid);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        child_failed(where, decoder, status, message);
    MappedFile file("/proc/self/fd/" + std::to_string(data.get()));
    const std::span<const std::byte> all = file.bytes();
    std::uint64_t length = 0;
    if (all.size() < 8) throw std::runtime_error(where + ": the reader handed over no volume");
    std::memcpy(&length, all.data(), 8);
    if (length > all.size() - 8)
        throw std::runtime_error(where + ": the reader's volume is cut short");
    const std::vector<std::byte> header(all.begin() + 8, all.begin() + 8 + std::ptrdiff_t(length));
    return decode_volume(header, std::move(file), voxels_offset(std::size_t(length)));
}

}  // namespace isowall::formats
