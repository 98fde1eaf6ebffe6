#pragma once
// Memory bounds of the server tests ("Nothing lies, nothing hangs, round two"): they read the
// process's resident set, which under AddressSanitizer holds its allocator's quarantine of freed
// blocks (256 MiB by default) rather than what the program keeps. There the tests run all the
// same and print their figures, but do not judge them.
namespace isowall::test {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kRssJudged = false;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kRssJudged = false;
#else
inline constexpr bool kRssJudged = true;
#endif
#else
inline constexpr bool kRssJudged = true;
#endif

}  // namespace isowall::test
