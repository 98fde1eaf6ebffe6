#include "volume/mapped_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace isowall {

MappedFile::MappedFile(const std::filesystem::path& path, bool populate) {
    // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer forever.
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) throw std::runtime_error(path.string() + ": cannot open: " + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
        const int err = errno;
        ::close(fd);
        throw std::runtime_error(path.string() + ": cannot stat: " + std::strerror(err));
    }
    if (!S_ISREG(st.st_mode)) {
        ::close(fd);
        throw std::runtime_error(path.string() + ": not a regular file");
    }
    size_ = static_cast<std::size_t>(st.st_size);
    if (size_ > 0) {
        const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
        const bool fits =
            pages > 0 && page > 0 &&
            size_ / static_cast<std::size_t>(page) <= static_cast<std::size_t>(pages) / 2;
        const int flags = MAP_SHARED | (populate && fits ? MAP_POPULATE : 0);
        void* p = ::mmap(nullptr, size_, PROT_READ, flags, fd, 0);
        if (p == MAP_FAILED) {
            const int err = errno;
            ::close(fd);
            throw std::runtime_error(path.string() + ": cannot map: " + std::strerror(err));
        }
        data_ = static_cast<const std::byte*>(p);
    }
    ::close(fd);  // the mapping keeps the file alive
}

MappedFile::MappedFile(MappedFile&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)), size_(std::exchange(other.size_, 0)) {}

MappedFile& MappedFile::operator=(MappedFile&& other) noexcept {
    if (this != &other) {
        if (data_) ::munmap(const_cast<std::byte*>(data_), size_);
        data_ = std::exchange(other.data_, nullptr);
        size_ = std::exchange(other.size_, 0);
    }
    return *this;
}

void MappedFile::release(std::span<const std::byte> part) const {
    if (!data_ || part.empty()) return;
    const auto lo = std::max(reinterpret_cast<std::uintptr_t>(part.data()),
                             reinterpret_cast<std::uintptr_t>(data_));
    const auto hi = std::min(reinterpret_cast<std::uintptr_t>(part.data() + part.size()),
                             reinterpret_cast<std::uintptr_t>(data_ + size_));
    if (lo >= hi) return;
    // madvise takes a page-aligned start; the page it rounds down into is the map's too.
    const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGE_SIZE));
    const std::uintptr_t start = lo / page * page;
    // Advice only: a map the kernel will not let go of keeps its pages, and nothing is lost.
    ::madvise(reinterpret_cast<void*>(start), hi - start, MADV_DONTNEED);
}

MappedFile::~MappedFile() {
    if (data_) ::munmap(const_cast<std::byte*>(data_), size_);
}

}  // namespace isowall
