// The store import's pace on this machine, for a node with more cores than the development box:
//   isowall_bench_import RAW.nrrd GZIP.nrrd OUT_FOLDER [--runs N]
// RAW.nrrd is imported from its memory map (as `isowall import` does for raw data); GZIP.nrrd is
// inflated a slab at a time, with the next slab decoded on a thread of its own while this one is
// compressed (the default) and without. Each line: seconds, MiB/s of voxels, the threads; the
// median of the runs, the configurations alternated. Built with a static C++ runtime and only
// isowall_store's libraries, so it can be copied to a node without ours.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/util.h"
#include "store/store_writer.h"
#include "volume/load_checks.h"
#include "volume/plane_source.h"

namespace fs = std::filesystem;
using namespace isowall;

namespace {

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// One import of `path` into `out`: seconds from the open to the store in place.
double import_once(const fs::path& path, const fs::path& out, int mode, int threads,
                   std::uint64_t& bytes) {
    store::ImportOptions o;
    o.replace = true;
    o.threads = threads;
    Stopwatch sw;
    if (mode == 0) {
        const Volume v = load_nrrd(path, false);
        bytes = v.bytes().size();
        store::write_store(v, out, o);
    } else {
        const auto planes = nrrd_planes(path, mode == 1);
        if (!planes) throw std::runtime_error(path.string() + ": not a gzip NRRD");
        bytes = voxel_bytes(planes->dims(), planes->type());
        store::write_store(*planes, out, o);
    }
    return sw.seconds();
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 4) {
        std::fprintf(stderr, "usage: %s RAW.nrrd GZIP.nrrd OUT_FOLDER [--runs N]\n", argv[0]);
        return 2;
    }
    int runs = 3;
    if (argc >= 6 && std::string(argv[4]) == "--runs") runs = std::max(1, std::atoi(argv[5]));
    const int threads = int(std::max(1u, std::thread::hardware_concurrency()));
    const char* names[] = {"raw, mapped", "gzip, decode read ahead", "gzip, decode in line"};
    std::vector<double> s[3];
    std::uint64_t bytes[3] = {};
    try {
        for (int r = 0; r < runs; ++r)
            for (int m = 0; m < 3; ++m)
                s[m].push_back(import_once(argv[m == 0 ? 1 : 2], fs::path(argv[3]) / "store", m,
                                           threads, bytes[m]));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_import: %s\n", e.what());
        return 1;
    }
    std::printf(
        "| source | seconds (median of %d) | MiB/s of voxels | threads |\n|---|---|---|---|\n",
        runs);
    for (int m = 0; m < 3; ++m)
        std::printf("| %s | %.2f | %.0f | %d |\n", names[m], median(s[m]),
                    double(bytes[m]) / (1 << 20) / median(s[m]), threads);
    std::printf("peak resident memory %.0f MiB\n", peak_rss_mib());
    return 0;
}
