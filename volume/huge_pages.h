#pragma once
// Volumes in transparent huge pages. A memory-mapped volume lives in 4 KiB page-cache pages, and
// the engine reads it at random: a ray's cells, a group's cells and their meta-cell corners at a
// stride of 2^level voxels, a z step apart by a whole slice. Past a few hundred MiB nearly every
// such read misses the TLB and walks the page tables. The 2048 head (3.9 GB) took 0.29 s to
// C = 99% on one thread from the map and 0.20 s from a copy in 2 MiB pages, every ray 0.94 s
// against 0.70 s (median of 4 runs each, interleaved); the 512 head (61 MB) did not change.
// Linux gives file pages no huge pages on ext4, so the volume is copied into anonymous memory
// advised with MADV_HUGEPAGE. The copy is the process's own, where the map was shared through the
// page cache by every rank on the machine, so the choice counts the copies a host would hold.
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace isowall {

enum class HugePages { automatic, on, off };

// "auto", "on", "off"; nullopt otherwise.
std::optional<HugePages> parse_huge_pages(std::string_view text);

// The kernel's transparent huge page mode: the bracketed word of
// /sys/kernel/mm/transparent_hugepage/enabled ("always [madvise] never" is madvise). An
// unreadable or unexpected text reads as never.
enum class ThpMode { always, madvise, never };
ThpMode parse_thp_mode(std::string_view enabled_text);
ThpMode thp_mode();

// "MemAvailable:" of /proc/meminfo in bytes; nullopt when absent.
std::optional<std::size_t> parse_mem_available(std::string_view meminfo_text);
std::optional<std::size_t> mem_available();

// Below this size the copy gained nothing measurable (the 512 head, 61 MB).
inline constexpr std::size_t kHugePagesMinBytes = std::size_t{256} << 20;

struct HugePagesChoice {
    bool copy = false;
    std::string why;  // one phrase for the progress line: why the volume stays mapped, or not
};

// Whether to copy a volume of `bytes` into huge pages. `copies_on_host`: how many processes on
// this machine would each hold a copy (the wall's tile ranks). auto copies a volume of at least
// kHugePagesMinBytes when the kernel grants huge pages on advice, every copy fits in half of the
// available memory and the process draws more than one frame (`one_frame`: a single `render`,
// whose copy would cost more than it saves: 0.4 s warm and 1.6 s from a cold cache for the
// engine block's 512 MiB copy, against a frame no faster than from the map; a frame from the map
// reads only the pages its rays and passes touch); on copies whenever the kernel grants them
// (throws InputError naming --huge-pages when it never does); off never copies.
HugePagesChoice choose_huge_pages(HugePages mode, std::size_t bytes, int copies_on_host,
                                  ThpMode thp, std::optional<std::size_t> available_bytes,
                                  bool one_frame = false);

// An anonymous, private, read-write mapping whose start is 2 MiB aligned, advised with
// MADV_HUGEPAGE (RAII, move-only). Throws std::runtime_error when the mapping fails.
class HugePageBuffer {
  public:
    static constexpr std::size_t kAlign = std::size_t{2} << 20;

    HugePageBuffer() = default;
    explicit HugePageBuffer(std::size_t size);
    HugePageBuffer(HugePageBuffer&& other) noexcept;
    HugePageBuffer& operator=(HugePageBuffer&& other) noexcept;
    HugePageBuffer(const HugePageBuffer&) = delete;
    HugePageBuffer& operator=(const HugePageBuffer&) = delete;
    ~HugePageBuffer();

    std::span<std::byte> bytes() const { return {data_, size_}; }
    std::size_t size() const { return size_; }

  private:
    void release();
    void* map_ = nullptr;  // what mmap returned
    std::size_t map_size_ = 0;
    std::byte* data_ = nullptr;  // the aligned start
    std::size_t size_ = 0;
};

}  // namespace isowall
