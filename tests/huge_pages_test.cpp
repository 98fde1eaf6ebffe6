// Volumes in huge pages (volume/huge_pages.h): the choice as a pure function, the kernel's
// texts parsed, the buffer's alignment and advice, and a copied volume that reads as before.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "tests/test_util.h"
#include "volume/huge_pages.h"
#include "volume/mapped_file.h"
#include "volume/octree.h"
#include "volume/phantom.h"
#include "volume/volume.h"

namespace isowall {
namespace {

constexpr std::size_t kMiB = std::size_t{1} << 20;

TEST(HugePages, ParsesItsOption) {
    EXPECT_EQ(parse_huge_pages("auto"), HugePages::automatic);
    EXPECT_EQ(parse_huge_pages("on"), HugePages::on);
    EXPECT_EQ(parse_huge_pages("off"), HugePages::off);
    EXPECT_EQ(parse_huge_pages(""), std::nullopt);
    EXPECT_EQ(parse_huge_pages("On"), std::nullopt);
    EXPECT_EQ(parse_huge_pages("auto "), std::nullopt);
}

TEST(HugePages, ReadsTheKernelsModeFromTheBracketedWord) {
    EXPECT_EQ(parse_thp_mode("always [madvise] never\n"), ThpMode::madvise);
    EXPECT_EQ(parse_thp_mode("[always] madvise never\n"), ThpMode::always);
    EXPECT_EQ(parse_thp_mode("always madvise [never]\n"), ThpMode::never);
    EXPECT_EQ(parse_thp_mode(""), ThpMode::never);  // no such file: read as empty
    EXPECT_EQ(parse_thp_mode("always madvise never"), ThpMode::never);
    EXPECT_EQ(parse_thp_mode("[always"), ThpMode::never);
    EXPECT_EQ(parse_thp_mode("[sometimes] always"), ThpMode::never);
}

TEST(HugePages, ReadsMemAvailableInBytes) {
    const std::string meminfo =
        "MemTotal:       24592056 kB\nMemFree:        22130440 kB\n"
        "MemAvailable:   23102344 kB\nBuffers:          120000 kB\n";
    EXPECT_EQ(parse_mem_available(meminfo), std::size_t{23102344} * 1024);
    EXPECT_EQ(parse_mem_available(""), std::nullopt);
    EXPECT_EQ(parse_mem_available("MemTotal: 100 kB\n"), std::nullopt);
    EXPECT_EQ(parse_mem_available("MemAvailable:   x kB\n"), std::nullopt);
    EXPECT_EQ(parse_mem_available("MemAvailable:   100 MB\n"), std::nullopt);
    EXPECT_EQ(parse_mem_available("MemAvailable:   99999999999999999999 kB\n"), std::nullopt);
    EXPECT_EQ(parse_mem_available("MemAvailable:"), std::nullopt);
    // The machine's own file has the line.
    EXPECT_TRUE(mem_available().has_value());
}

TEST(HugePages, ChoosesByModeKernelSizeAndMemory) {
    const std::size_t big = 3900 * kMiB, small = 61 * kMiB, avail = 22 * 1024 * kMiB;
    // off never copies, whatever else holds.
    EXPECT_FALSE(choose_huge_pages(HugePages::off, big, 1, ThpMode::madvise, avail).copy);
    // A kernel without huge pages: auto keeps the map; on is an error naming the option.
    const auto none = choose_huge_pages(HugePages::automatic, big, 1, ThpMode::never, avail);
    EXPECT_FALSE(none.copy);
    EXPECT_NE(none.why.find("no huge pages"), std::string::npos) << none.why;
    try {
        choose_huge_pages(HugePages::on, small, 1, ThpMode::never, avail);
        ADD_FAILURE() << "on with a kernel that never grants huge pages did not throw";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--huge-pages"), std::string::npos) << e.what();
    }
    // One frame (a single render): auto keeps the map; on still copies.
    const auto once =
        choose_huge_pages(HugePages::automatic, big, 1, ThpMode::madvise, avail, true);
    EXPECT_FALSE(once.copy);
    EXPECT_NE(once.why.find("one frame"), std::string::npos) << once.why;
    EXPECT_TRUE(choose_huge_pages(HugePages::automatic, big, 1, ThpMode::madvise, avail).copy);
    EXPECT_TRUE(choose_huge_pages(HugePages::on, big, 1, ThpMode::madvise, avail, true).copy);
    // on copies any size, with either mode that grants them, even when memory is unknown.
    EXPECT_TRUE(choose_huge_pages(HugePages::on, small, 1, ThpMode::madvise, avail).copy);
    EXPECT_TRUE(choose_huge_pages(HugePages::on, 1, 25, ThpMode::always, std::nullopt).copy);
    // auto: the size threshold, exactly at it and one byte under.
    const auto under = choose_huge_pages(HugePages::automatic, small, 1, ThpMode::madvise, avail);
    EXPECT_FALSE(under.copy);
    EXPECT_NE(under.why.find("256 MiB"), std::string::npos) << under.why;
    EXPECT_TRUE(
        choose_huge_pages(HugePages::automatic, kHugePagesMinBytes, 1, ThpMode::madvise, avail)
            .copy);
    EXPECT_FALSE(
        choose_huge_pages(HugePages::automatic, kHugePagesMinBytes - 1, 1, ThpMode::always, avail)
            .copy);
    // auto: every copy on the host in half of what is available.
    EXPECT_TRUE(choose_huge_pages(HugePages::automatic, big, 1, ThpMode::madvise, avail).copy);
    EXPECT_TRUE(choose_huge_pages(HugePages::automatic, big, 2, ThpMode::madvise, avail).copy);
    const auto four = choose_huge_pages(HugePages::automatic, big, 4, ThpMode::madvise, avail);
    EXPECT_FALSE(four.copy);
    EXPECT_NE(four.why.find("4 copies"), std::string::npos) << four.why;
    EXPECT_TRUE(
        choose_huge_pages(HugePages::automatic, 1000 * kMiB, 4, ThpMode::madvise, 8000 * kMiB)
            .copy);
    EXPECT_FALSE(
        choose_huge_pages(HugePages::automatic, 1001 * kMiB, 4, ThpMode::madvise, 8000 * kMiB)
            .copy);
    EXPECT_FALSE(
        choose_huge_pages(HugePages::automatic, big, 1, ThpMode::madvise, std::nullopt).copy);
    // Zero or negative copies read as one.
    EXPECT_TRUE(choose_huge_pages(HugePages::automatic, big, 0, ThpMode::madvise, avail).copy);
}

// The VmFlags line of the /proc/self/smaps entry that holds `p`.
std::string vm_flags_of(const void* p) {
    std::ifstream in("/proc/self/smaps");
    const auto at = reinterpret_cast<std::uintptr_t>(p);
    std::string line;
    bool inside = false;
    while (std::getline(in, line)) {
        std::uintptr_t lo = 0, hi = 0;
        char dash = 0;
        std::istringstream head(line);
        if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
            inside = lo <= at && at < hi;
        } else if (inside && line.rfind("VmFlags:", 0) == 0) {
            return line;
        }
    }
    return {};
}

TEST(HugePages, BufferIsAlignedWritableAdvisedAndMoves) {
    HugePageBuffer empty(0);
    EXPECT_EQ(empty.size(), 0u);
    EXPECT_TRUE(empty.bytes().empty());

    const std::size_t size = 3 * kMiB + 5;
    HugePageBuffer a(size);
    ASSERT_EQ(a.size(), size);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(a.bytes().data()) % HugePageBuffer::kAlign, 0u);
    for (std::size_t i = 0; i < size; i += 4093) a.bytes()[i] = std::byte(i & 0xff);
    a.bytes()[size - 1] = std::byte{0x5a};
    if (thp_mode() != ThpMode::never) {
        const std::string flags = vm_flags_of(a.bytes().data());
        EXPECT_NE(flags.find(" hg"), std::string::npos) << "no MADV_HUGEPAGE advice: " << flags;
    }
    const std::byte* data = a.bytes().data();
    HugePageBuffer b(std::move(a));
    EXPECT_EQ(a.size(), 0u);  // NOLINT(bugprone-use-after-move): moved-from is empty
    EXPECT_EQ(b.bytes().data(), data);
    EXPECT_EQ(b.bytes()[size - 1], std::byte{0x5a});
    EXPECT_EQ(b.bytes()[4093], std::byte(4093 & 0xff));
    HugePageBuffer c(kMiB);
    c = std::move(b);
    EXPECT_EQ(c.bytes().data(), data);
    EXPECT_EQ(c.size(), size);

    // No machine maps 4 EiB: an error naming the size, which open_volume turns into keeping
    // the map (auto) or an error naming --huge-pages (on).
    try {
        HugePageBuffer huge(std::size_t{1} << 62);
        ADD_FAILURE() << "mapped 4 EiB";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("cannot map"), std::string::npos) << e.what();
    }
}

template <class T>
std::vector<T> nodes_of(const Volume& v) {
    const auto o = MinMaxOctree<T>::build(v.view<T>());
    return {o.nodes().begin(), o.nodes().end()};
}

TEST(HugePages, CopiedVolumesReadAsBefore) {
    // An owned volume (the phantom).
    Volume phantom = make_phantom();
    const std::vector<std::byte> before(phantom.bytes().begin(), phantom.bytes().end());
    const auto nodes = nodes_of<std::uint8_t>(phantom);
    phantom.copy_to_huge_pages();
    EXPECT_TRUE(phantom.in_huge_pages());
    EXPECT_FALSE(phantom.mapped());
    ASSERT_EQ(phantom.bytes().size(), before.size());
    EXPECT_TRUE(std::equal(before.begin(), before.end(), phantom.bytes().begin()));
    EXPECT_EQ(nodes_of<std::uint8_t>(phantom), nodes);
    // Moved, it still reads the same bytes (the buffer moves with it).
    const Volume moved = std::move(phantom);
    EXPECT_TRUE(std::equal(before.begin(), before.end(), moved.bytes().begin()));

    // A memory-mapped raw volume with a header to skip, 16-bit.
    const auto dir = test::scratch_dir("huge_pages");
    std::vector<std::uint16_t> voxels(9 * 7 * 5);
    for (std::size_t i = 0; i < voxels.size(); ++i) voxels[i] = std::uint16_t(i * 2654435761u);
    {
        std::ofstream out(dir / "v.raw", std::ios::binary);
        out << "HEAD";
        out.write(reinterpret_cast<const char*>(voxels.data()), std::streamsize(voxels.size() * 2));
    }
    RawSpec spec;
    spec.dims = {9, 7, 5};
    spec.type = VoxelType::u16;
    spec.header_bytes = 4;
    Volume v = load_volume(dir / "v.raw", spec);
    ASSERT_TRUE(v.mapped());
    v.copy_to_huge_pages();
    EXPECT_FALSE(v.mapped());
    EXPECT_TRUE(v.in_huge_pages());
    EXPECT_EQ(v.files().size(), 1u);  // the octree cache key still covers the file
    const auto view = v.view<std::uint16_t>();
    for (std::size_t i = 0; i < voxels.size(); ++i) {
        const glm::ivec3 p(int(i % 9), int(i / 9 % 7), int(i / 63));
        ASSERT_EQ(view.at(p.x, p.y, p.z), voxels[i]) << "voxel " << i;
    }
}

// The resident bytes of the mapping that holds `at`, from /proc/self/smaps (its "Rss:" line).
std::size_t resident_bytes(const void* at) {
    std::ifstream smaps("/proc/self/smaps");
    const auto a = reinterpret_cast<std::uintptr_t>(at);
    bool inside = false;
    for (std::string line; std::getline(smaps, line);) {
        std::uintptr_t lo = 0, hi = 0;
        char dash = 0;
        std::istringstream range(line);
        if (range >> std::hex >> lo >> dash >> hi && dash == '-') {
            inside = lo <= a && a < hi;
        } else if (inside && line.rfind("Rss:", 0) == 0) {
            return std::stoull(line.substr(4)) * 1024;
        }
    }
    ADD_FAILURE() << "no mapping holds the address in /proc/self/smaps";
    return 0;
}

TEST(HugePages, AMapLetsGoOfThePartsItWasAskedTo) {
    const auto dir = test::scratch_dir("huge_pages_release");
    const std::size_t size = 8 * kMiB;
    {
        std::vector<char> bytes(size);
        for (std::size_t i = 0; i < size; ++i) bytes[i] = char(i * 131 >> 7);
        std::ofstream(dir / "f.bin", std::ios::binary).write(bytes.data(), std::streamsize(size));
    }
    const MappedFile map(dir / "f.bin", true);
    const auto all = map.bytes();
    std::size_t sum = 0;
    for (std::size_t i = 0; i < size; i += 4096) sum += std::to_integer<unsigned>(all[i]);
    EXPECT_GE(resident_bytes(all.data()), size);
    // At least the part goes (a kernel that maps the file in large pages may drop the whole
    // large page around the part's end, which a later read maps again).
    map.release(all.first(size / 2 + 100));
    EXPECT_LE(resident_bytes(all.data()), size / 2);
    map.release(all.subspan(size / 2));
    EXPECT_EQ(resident_bytes(all.data()), 0u);
    // What was let go of reads as before.
    std::size_t again = 0;
    for (std::size_t i = 0; i < size; i += 4096) again += std::to_integer<unsigned>(all[i]);
    EXPECT_EQ(again, sum);
    EXPECT_EQ(all[size - 1], std::byte(char((size - 1) * 131 >> 7)));
}

// A volume of several of the copy's parts (64 MiB each), after a header: every voxel arrives.
TEST(HugePages, AVolumeOfSeveralPartsIsCopiedWhole) {
    const auto dir = test::scratch_dir("huge_pages_parts");
    const glm::ivec3 dims(1024, 1024, 130);  // 130 MiB: two whole parts and a short one
    const std::size_t n = std::size_t(dims.x) * dims.y * dims.z;
    auto value = [](std::size_t i) { return std::uint8_t((i * 2654435761u) >> 13); };
    {
        std::vector<std::uint8_t> voxels(n);
        for (std::size_t i = 0; i < n; ++i) voxels[i] = value(i);
        std::ofstream out(dir / "v.raw", std::ios::binary);
        out << "HEADER";
        out.write(reinterpret_cast<const char*>(voxels.data()), std::streamsize(n));
    }
    RawSpec spec;
    spec.dims = dims;
    spec.type = VoxelType::u8;
    spec.header_bytes = 6;
    Volume v = load_volume(dir / "v.raw", spec);
    ASSERT_TRUE(v.mapped());
    v.copy_to_huge_pages();
    ASSERT_TRUE(v.in_huge_pages());
    const auto bytes = v.bytes();
    ASSERT_EQ(bytes.size(), n);
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < n; ++i) wrong += bytes[i] != std::byte{value(i)};
    EXPECT_EQ(wrong, 0u);
}

}  // namespace
}  // namespace isowall
