// isowall-cores: how much faster two threads do twice one thread's work on this machine, for two
// kinds of work: arithmetic in registers (what more cores always speed up) and reads at random
// places of a table far larger than the caches (what a ray walking an octree and a volume does,
// where the cores share the memory system). Each figure is the best of --reps runs. Prints
// "key value" lines, which scripts/bench_scaling.py reads:
//
//   isowall-cores [--table-mib 256] [--reps 3]
//
// alu_speedup and memory_speedup are (2 x one thread's time) / two threads' time: 2 is perfect.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

std::uint64_t arithmetic(std::uint64_t steps, std::uint64_t seed) {
    std::uint64_t x = seed | 1;
    for (std::uint64_t i = 0; i < steps; ++i) {
        x = x * 6364136223846793005ULL + 1442695040888963407ULL;
        x ^= x >> 13;
    }
    return x;
}

// Reads at pseudo-random places (independent of the values read, so the core may have several
// reads in flight, as a ray caster's neighbouring rays do).
std::uint64_t random_reads(const std::vector<std::uint32_t>& table, std::uint64_t steps,
                           std::uint32_t seed) {
    const std::size_t mask = table.size() - 1;
    std::uint64_t sum = 0;
    std::uint32_t j = seed;
    for (std::uint64_t i = 0; i < steps; ++i) {
        j = j * 1664525u + 1013904223u;
        sum += table[j & mask];
    }
    return sum;
}

// Seconds for `threads` threads each running work(t) once.
template <class Work>
double timed(int threads, const Work& work) {
    const auto t0 = Clock::now();
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(work, t);
    for (std::thread& th : pool) th.join();
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct Pair {
    double one_s = 1e30, two_s = 1e30;
};

template <class Work>
Pair best_of(int reps, const Work& work) {
    Pair p;
    for (int r = 0; r < reps; ++r) {
        p.one_s = std::min(p.one_s, timed(1, work));
        p.two_s = std::min(p.two_s, timed(2, work));
    }
    return p;
}

int usage(const char* why) {
    std::fprintf(stderr,
                 "isowall-cores: error: %s (usage: isowall-cores [--table-mib N] [--reps N])\n",
                 why);
    return 1;
}

}  // namespace

int main(int argc, char** argv) {
    long table_mib = 256, reps = 3;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
            std::printf(
                "Usage: isowall-cores [--table-mib N] [--reps N]\n"
                "How much faster two threads do twice one thread's work here: arithmetic in\n"
                "registers (alu_speedup) and random reads over a table of N MiB (memory_speedup,\n"
                "default 256); 2 is perfect. Each figure is the best of --reps runs (default 3).\n"
                "Prints \"key value\" lines.\n");
            return 0;
        }
        const bool has_value = i + 1 < argc;
        long* target = std::strcmp(argv[i], "--table-mib") == 0 ? &table_mib
                       : std::strcmp(argv[i], "--reps") == 0    ? &reps
                                                                : nullptr;
        if (!target) return usage((std::string("unknown option ") + argv[i]).c_str());
        if (!has_value) return usage((std::string(argv[i]) + ": a value is needed").c_str());
        char* end = nullptr;
        *target = std::strtol(argv[++i], &end, 10);
        if (*end != '\0' || *target < 1 || *target > 4096)
            return usage((std::string(argv[i - 1]) + ": expected an integer in [1, 4096]").c_str());
    }
    // A power of two of 4-byte entries, at least the MiB asked.
    std::size_t entries = 1;
    while (entries * sizeof(std::uint32_t) < static_cast<std::size_t>(table_mib) << 20)
        entries *= 2;
    std::vector<std::uint32_t> table(entries);
    for (std::size_t i = 0; i < entries; ++i)
        table[i] = static_cast<std::uint32_t>(i * 2654435761u);

    volatile std::uint64_t sink = 0;
    const Pair alu = best_of(static_cast<int>(reps), [&](int t) {
        sink = sink + arithmetic(200'000'000, static_cast<std::uint64_t>(t) + 1);
    });
    const Pair mem = best_of(static_cast<int>(reps), [&](int t) {
        sink = sink + random_reads(table, 20'000'000, static_cast<std::uint32_t>(t) * 7919u + 1);
    });
    std::printf("table_mib %zu\nalu_1t_s %.4f\nalu_2t_s %.4f\nalu_speedup %.3f\n",
                (entries * sizeof(std::uint32_t)) >> 20, alu.one_s, alu.two_s,
                2 * alu.one_s / alu.two_s);
    std::printf("memory_1t_s %.4f\nmemory_2t_s %.4f\nmemory_speedup %.3f\n", mem.one_s, mem.two_s,
                2 * mem.one_s / mem.two_s);
    return 0;
}
