#include "core/util.h"

#include <malloc.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>
#include <csignal>

#include <algorithm>
#include <charconv>
#include <fstream>

namespace isowall {

void keep_freed_memory() {
    // Trimming the top of a heap is what gives freed pages back; blocks of 32 MiB and more (the
    // largest threshold glibc takes) are still mapped and unmapped on their own.
    mallopt(M_TRIM_THRESHOLD, static_cast<int>(kKeepFreedBytes));
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
}

int cores_allowed() {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) != 0) return 1;
    return std::max(1, CPU_COUNT(&set));
}

long voluntary_switches() {
    rusage ru{};
    getrusage(RUSAGE_THREAD, &ru);
    return ru.ru_nvcsw;
}

double peak_rss_mib() {
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    return static_cast<double>(ru.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

double current_rss_mib() {
    std::ifstream statm("/proc/self/statm");
    long pages_total = 0, pages_resident = 0;
    statm >> pages_total >> pages_resident;
    return static_cast<double>(pages_resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) /
           (1024.0 * 1024.0);
}

std::optional<glm::ivec2> parse_size(std::string_view s) {
    const auto x = s.find('x');
    if (x == std::string_view::npos) return std::nullopt;
    int w = 0, h = 0;
    const auto a = std::from_chars(s.data(), s.data() + x, w);
    const auto b = std::from_chars(s.data() + x + 1, s.data() + s.size(), h);
    if (a.ec != std::errc() || a.ptr != s.data() + x) return std::nullopt;
    if (b.ec != std::errc() || b.ptr != s.data() + s.size()) return std::nullopt;
    if (w <= 0 || h <= 0 || w > 32768 || h > 32768) return std::nullopt;
    return glm::ivec2(w, h);
}

}  // namespace isowall
