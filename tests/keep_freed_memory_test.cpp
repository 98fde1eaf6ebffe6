// keep_freed_memory (core/util.h): memory a frame frees stays in the process for the next
// frame instead of going back to the kernel.
#include <gtest/gtest.h>

#include <malloc.h>

#include <cstdlib>
#include <cstring>
#include <vector>

#include "core/util.h"

namespace isowall {
namespace {

// 128 blocks of 256 KiB, written and freed: by default glibc maps blocks this size one by one and
// unmaps each on free; kept, they come from the heap and stay there as free space.
std::size_t free_bytes_after_blocks() {
    constexpr std::size_t kBlock = std::size_t(256) << 10, kBlocks = 128;
    std::vector<char*> blocks;
    for (std::size_t i = 0; i < kBlocks; ++i) {
        auto* p = static_cast<char*>(std::malloc(kBlock));
        if (!p) return 0;
        std::memset(p, 1, kBlock);
        blocks.push_back(p);
    }
    for (char* p : blocks) std::free(p);
    return mallinfo2().fordblks;
}

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitizerAllocator = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitizerAllocator = true;
#else
constexpr bool kSanitizerAllocator = false;
#endif
#else
constexpr bool kSanitizerAllocator = false;
#endif

TEST(KeepFreedMemory, FreedBlocksStayInTheProcess) {
    if (kSanitizerAllocator)
        GTEST_SKIP() << "AddressSanitizer's allocator stands in for the C library's: mallopt and "
                        "mallinfo2 do not apply";
    if (std::getenv("ISOWALL_TEST_DEFAULT_MALLOC")) {
        // The check of the check: without the call, the same blocks leave the process.
        EXPECT_LT(free_bytes_after_blocks(), std::size_t(8) << 20);
        return;
    }
    keep_freed_memory();
    EXPECT_GE(free_bytes_after_blocks(), std::size_t(32) << 20);
}

}  // namespace
}  // namespace isowall
