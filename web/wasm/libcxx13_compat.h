// Forced into every file web/wasm/build.sh compiles (-include): what the project's C++20 uses that
// the libc++ 13 of Debian 12's emscripten 3.1.6 lacks. Each shim stands only where the library
// does not provide the feature itself, so a newer emscripten compiles the sources unchanged.
#pragma once
#include <bit>

#ifndef __cpp_lib_bit_cast
namespace std {
// libc++ 14's own definition: clang 14 has the builtin.
template <class To, class From>
requires(sizeof(To) == sizeof(From) && is_trivially_copyable_v<To> &&
         is_trivially_copyable_v<From>) constexpr To bit_cast(const From& from) noexcept {
    return __builtin_bit_cast(To, from);
}
}  // namespace std
#endif
