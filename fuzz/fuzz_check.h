#pragma once
// What the harnesses share. A harness calls one parser on the fuzzer's bytes; our documented
// errors (InputError, WireError) are the parser saying no, which is fine. Anything else is a
// finding: a crash, a sanitizer report, another exception (it escapes the harness and aborts), a
// hang, or a parse that succeeds with a value the rest of the program cannot use (check() below:
// one line naming the property, then abort, which libFuzzer and the replay test both report).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

// libFuzzer's entry point; the replay test (replay_main.cpp) calls it too.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace isowall::fuzz {

inline void check(bool ok, const char* property) {
    if (ok) return;
    std::fprintf(stderr, "fuzz: a parse succeeded but broke a property: %s\n", property);
    std::abort();
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
    return {reinterpret_cast<const char*>(data), size};
}

}  // namespace isowall::fuzz
