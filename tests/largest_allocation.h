#pragma once
// The largest single allocation made while a function runs: to show that a decoder refuses a
// huge count before it allocates. largest_allocation.cpp replaces the global operator new, so a
// test executable that lists it in its SOURCES has every allocation recorded (sizes only).
#include <cstddef>
#include <functional>

namespace isowall::test {

std::size_t largest_allocation_in(const std::function<void()>& f);

}  // namespace isowall::test
