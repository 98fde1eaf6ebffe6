#include "volume/huge_pages.h"

#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "core/error.h"

namespace isowall {

std::optional<HugePages> parse_huge_pages(std::string_view text) {
    if (text == "auto") return HugePages::automatic;
    if (text == "on") return HugePages::on;
    if (text == "off") return HugePages::off;
    return std::nullopt;
}

ThpMode parse_thp_mode(std::string_view text) {
    const auto open = text.find('[');
    const auto close = text.find(']', open == std::string_view::npos ? 0 : open);
    if (open == std::string_view::npos || close == std::string_view::npos) return ThpMode::never;
    const std::string_view word = text.substr(open + 1, close - open - 1);
    if (word == "always") return ThpMode::always;
    if (word == "madvise") return ThpMode::madvise;
    return ThpMode::never;
}

namespace {

std::string read_small_file(const char* path) {
    std::ifstream in(path);
    std::ostringstream os;
    os << in.rdbuf();
    return os.str();
}

std::string mib(std::size_t bytes) {
    return std::to_string((bytes + (std::size_t{1} << 19)) >> 20) + " MiB";
}

}  // namespace

ThpMode thp_mode() {
    return parse_thp_mode(read_small_file("/sys/kernel/mm/transparent_hugepage/enabled"));
}

std::optional<std::size_t> parse_mem_available(std::string_view text) {
    constexpr std::string_view kKey = "MemAvailable:";
    auto at = text.find(kKey);
    if (at == std::string_view::npos) return std::nullopt;
    at = text.find_first_not_of(' ', at + kKey.size());
    if (at == std::string_view::npos) return std::nullopt;
    std::uint64_t kib = 0;
    const auto [end, ec] = std::from_chars(text.data() + at, text.data() + text.size(), kib);
    if (ec != std::errc{} || kib > (std::uint64_t{1} << 53)) return std::nullopt;
    if (std::string_view(end, static_cast<std::size_t>(text.data() + text.size() - end))
            .substr(0, 3) != " kB")
        return std::nullopt;
    return static_cast<std::size_t>(kib) * 1024;
}

std::optional<std::size_t> mem_available() {
    return parse_mem_available(read_small_file("/proc/meminfo"));
}

HugePagesChoice choose_huge_pages(HugePages mode, std::size_t bytes, int copies_on_host,
                                  ThpMode thp, std::optional<std::size_t> available_bytes,
                                  bool one_frame) {
    if (mode == HugePages::off) return {false, "--huge-pages off"};
    if (thp == ThpMode::never) {
        if (mode == HugePages::on)
            throw InputError("--huge-pages", "on",
                             "the kernel grants no transparent huge pages "
                             "(/sys/kernel/mm/transparent_hugepage/enabled is never)");
        return {false, "the kernel grants no huge pages"};
    }
    if (mode == HugePages::on) return {true, "--huge-pages on"};
    if (bytes < kHugePagesMinBytes) return {false, "under " + mib(kHugePagesMinBytes)};
    if (one_frame) return {false, "one frame: the copy would cost more than it saves"};
    const std::size_t copies = static_cast<std::size_t>(std::max(1, copies_on_host));
    if (!available_bytes || bytes > *available_bytes / 2 / copies)
        return {false, std::to_string(copies) + " cop" + (copies == 1 ? "y" : "ies") +
                           " would not fit in half of " +
                           (available_bytes ? mib(*available_bytes) : "unknown") + " available"};
    return {true, "auto"};
}

HugePageBuffer::HugePageBuffer(std::size_t size) {
    if (size == 0) return;
    // One extra huge page of slack so that an aligned start always exists inside the mapping.
    map_size_ = (size + kAlign - 1) / kAlign * kAlign + kAlign;
    void* p =
        ::mmap(nullptr, map_size_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) {
        map_size_ = 0;
        throw std::runtime_error("cannot map " + mib(size) +
                                 " for huge pages: " + std::strerror(errno));
    }
    map_ = p;
    const auto start = reinterpret_cast<std::uintptr_t>(p);
    data_ = reinterpret_cast<std::byte*>((start + kAlign - 1) / kAlign * kAlign);
    size_ = size;
    // Advice only: a kernel without huge pages leaves the buffer in small ones, which still works.
    ::madvise(data_, (size_ + kAlign - 1) / kAlign * kAlign, MADV_HUGEPAGE);
}

HugePageBuffer::HugePageBuffer(HugePageBuffer&& other) noexcept
    : map_(std::exchange(other.map_, nullptr)),
      map_size_(std::exchange(other.map_size_, 0)),
      data_(std::exchange(other.data_, nullptr)),
      size_(std::exchange(other.size_, 0)) {}

HugePageBuffer& HugePageBuffer::operator=(HugePageBuffer&& other) noexcept {
    if (this != &other) {
        release();
        map_ = std::exchange(other.map_, nullptr);
        map_size_ = std::exchange(other.map_size_, 0);
        data_ = std::exchange(other.data_, nullptr);
        size_ = std::exchange(other.size_, 0);
    }
    return *this;
}

HugePageBuffer::~HugePageBuffer() {
    release();
}

void HugePageBuffer::release() {
    if (map_) ::munmap(map_, map_size_);
    map_ = nullptr;
}

}  // namespace isowall
