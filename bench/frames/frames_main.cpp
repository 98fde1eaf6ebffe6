// isowall-bench-frames: a help frame's per-job renderer cost (resize, clear, read-back) when a
// rank's regions change size: now and then a tile-sized one, mostly small ones. A software
// rasteriser clears the whole buffers, so small frames in buffers kept from a large one once cost
// 10x a small frame's own (render/gl_core.cpp shrinks them now). Prints microseconds of thread
// CPU per job, the small frames beside those of a renderer that never had a large one.
#include <cstdio>
#include <ctime>
#include <exception>
#include <string>

#include "common/core/image.h"
#include "render/renderer.h"

namespace {

double cpu_s() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Costs {
    double large_us = 0, small_us = 0;
};

// 10 rounds of one 1024x768 job (when `with_large`) and 20 small ones of varied sizes.
Costs run(isowall::Renderer& r, bool with_large) {
    isowall::Image img;
    double large = 0, small = 0;
    int n_large = 0, n_small = 0;
    for (int round = 0; round < 10; ++round) {
        if (with_large) {
            const double c0 = cpu_s();
            r.resize(1024, 768);
            r.clear();
            r.read_back(img);
            large += cpu_s() - c0;
            ++n_large;
        }
        for (int i = 0; i < 20; ++i) {
            const double c0 = cpu_s();
            r.resize(64 + 16 * (i % 7), 48 + 16 * (i % 5));
            r.clear();
            r.read_back(img);
            small += cpu_s() - c0;
            ++n_small;
        }
    }
    return {n_large ? large / n_large * 1e6 : 0, small / n_small * 1e6};
}

}  // namespace

int main(int argc, char** argv) {
    const std::string backend = argc > 1 ? argv[1] : "osmesa";
    if (argc > 2 || backend == "--help" || backend == "-h") {
        std::printf("usage: isowall-bench-frames [osmesa|egl]\n");
        return argc > 2 ? 1 : 0;
    }
    try {
        auto mixed = isowall::make_renderer(backend);
        auto only_small = isowall::make_renderer(backend);
        run(*mixed, true);  // warm-up: first-touch pages, shader compiles
        run(*only_small, false);
        const Costs m = run(*mixed, true);
        const Costs s = run(*only_small, false);
        std::printf(
            "%s: per help job (resize, clear, read-back), thread CPU: 1024x768 %.0f us; "
            "64-160 x 48-112 after large ones %.0f us, on a renderer with small frames "
            "only %.0f us (%.2fx)\n",
            backend.c_str(), m.large_us, m.small_us, s.small_us, m.small_us / s.small_us);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "isowall-bench-frames: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
