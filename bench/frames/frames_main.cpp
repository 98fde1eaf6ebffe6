// isowall-bench-frames: a help frame's per-job renderer cost (resize, clear, read-back) when a
// rank's regions change size: now and then a tile-sized one, mostly small ones. A software
// rasteriser clears the whole buffers, so small frames in buffers kept from a large one once cost
// 10x a small frame's own (render/gl_core.cpp shrinks them now). Prints microseconds of thread
// CPU per job, the small frames beside those of a renderer that never had a large one.
// Then a rank's first help job after start-up, on a renderer warmed by warm_up() against one
// warmed by a single draw (warm_up()'s old way), each in a fresh process: Mesa sets up a
// path on its first use in a process.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/image.h"
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

isowall::Mesh triangle() {
    isowall::Mesh tri;
    tri.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    tri.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    tri.indices = {0, 1, 2};
    return tri;
}

// A help job as a wall rank's first: a small frame drawn, read back and its coverage read.
double first_job_us(isowall::Renderer& r) {
    const isowall::Mesh tri = triangle();
    isowall::Image img;
    std::vector<std::uint8_t> covered;
    const isowall::PixelRect rect{0, 0, 128, 96};
    const double c0 = cpu_s();
    r.resize(128, 96);
    r.clear();
    r.draw(tri, glm::mat4(1.0f), glm::mat4(1.0f));
    r.read_back(img, rect);
    r.read_coverage(covered, rect);
    return (cpu_s() - c0) * 1e6;
}

// first_job_us in a child process, its renderer warmed in full or by one draw alone; -1 when
// the child failed.
double first_job_in_child(const std::string& backend, bool full_warm_up) {
    int fds[2];
    if (pipe(fds) != 0) return -1;
    const pid_t child = fork();
    if (child == 0) {
        close(fds[0]);
        double us = -1;
        try {
            auto r = isowall::make_renderer(backend);
            if (full_warm_up) {
                isowall::warm_up(*r);
            } else {
                r->resize(16, 16);
                r->clear();
                r->draw(triangle(), glm::mat4(1.0f), glm::mat4(1.0f));
                r->finish();
            }
            us = first_job_us(*r);
        } catch (const std::exception&) {
        }
        const bool ok = write(fds[1], &us, sizeof(us)) == sizeof(us);
        _exit(ok ? 0 : 1);
    }
    close(fds[1]);
    double us = -1;
    if (child < 0 || read(fds[0], &us, sizeof(us)) != sizeof(us)) us = -1;
    close(fds[0]);
    if (child > 0) waitpid(child, nullptr, 0);
    return us;
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
        // Medians of 5 fresh processes each, alternating.
        std::vector<double> full, draw_only;
        for (int i = 0; i < 5; ++i) {
            full.push_back(first_job_in_child(backend, true));
            draw_only.push_back(first_job_in_child(backend, false));
        }
        std::sort(full.begin(), full.end());
        std::sort(draw_only.begin(), draw_only.end());
        if (full[2] < 0 || draw_only[2] < 0) throw std::runtime_error("a child renderer failed");
        std::printf(
            "%s: a rank's first help job (128x96: draw, read-back, coverage), thread CPU, median "
            "of 5 fresh processes: after warm_up %.0f us, after one draw only %.0f us (%.2fx)\n",
            backend.c_str(), full[2], draw_only[2], draw_only[2] / full[2]);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "isowall-bench-frames: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
