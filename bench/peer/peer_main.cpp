// isowall-peer: the ray side of the FE + Embree peer. It reads a mesh written by
// scripts/fe_mesh.py (flying edges in VTK), builds an Embree BVH over it and casts one primary
// ray per pixel of the front full view, the view `isowall render` draws by default. Prints
// "key value" lines for scripts/bench_scaling.py: triangles, bvh_s, rays_s, hit_pixels. With
// --repeat N the build and the rays run N times in the process and the last run is printed (the
// first as bvh_first_s and rays_first_s): the steady state `isowall render --warm-up` measures.
#include <cstdio>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>

#include "bench/peer/peer_mesh.h"
#include "bench/peer/peer_trace.h"
#include "core/error.h"
#include "core/image.h"
#include "core/util.h"
#include "files/image_io.h"

namespace {

using namespace isowall;

// White where a ray hit, black elsewhere: to look at beside `isowall render`'s picture.
void write_mask(const std::string& path, const peer::TraceResult& r, int width, int height) {
    Image img;
    img.width = width;
    img.height = height;
    img.rgba.assign(std::size_t(width) * std::size_t(height) * 4, 255);
    img.depth.assign(std::size_t(width) * std::size_t(height), 1.0f);
    for (std::size_t i = 0; i < r.hits.size(); ++i)
        for (std::size_t c = 0; c < 3; ++c) img.rgba[4 * i + c] = r.hits[i] ? 255 : 0;
    write_image(path, img);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{
        "isowall-peer: an Embree BVH and 8-wide primary rays over a mesh file, front view"};
    std::string mesh_path, size = "1600x1200", mask_out;
    int threads = 2, repeat = 1;
    app.add_option("mesh", mesh_path, "mesh file from scripts/fe_mesh.py")->required();
    app.add_option("--size", size, "screen WIDTHxHEIGHT")->capture_default_str();
    app.add_option("--threads", threads, "threads for the BVH build and the rays")
        ->check(CLI::Range(1, 256))
        ->capture_default_str();
    app.add_option("--repeat", repeat, "runs of the build and the rays; the last is printed")
        ->check(CLI::Range(1, 20))
        ->capture_default_str();
    app.add_option("--mask-out", mask_out, "write the hit pixels as an image (white = hit)");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);
        std::fprintf(stderr, "isowall-peer: error: %s (see --help)\n", clip(e.what(), 400).c_str());
        return 1;
    }
    try {
        const auto wh = parse_size(size);
        if (!wh) throw InputError("--size", "value", "expected WIDTHxHEIGHT, got " + quote(size));
        const peer::PeerMesh mesh = peer::read_peer_mesh(mesh_path);
        const peer::TraceView view = peer::front_view(mesh.bounds, wh->x, wh->y);
        const peer::TraceResult first = peer::trace(mesh, view, threads);
        peer::TraceResult r = first;
        for (int i = 1; i < repeat; ++i) r = peer::trace(mesh, view, threads);
        std::printf(
            "triangles %zu\nthreads %d\nbvh_s %.4f\nrays_s %.4f\nbvh_first_s %.4f\nrays_first_s "
            "%.4f\nhit_pixels %zu\n",
            mesh.triangle_count(), threads, r.bvh_s, r.rays_s, first.bvh_s, first.rays_s,
            r.hit_pixels);
        if (!mask_out.empty()) write_mask(mask_out, r, wh->x, wh->y);
    } catch (const std::exception& e) {
        std::fflush(stdout);
        std::fprintf(stderr, "isowall-peer: error: %s\n", clip(e.what(), 400).c_str());
        return 1;
    }
    return 0;
}
