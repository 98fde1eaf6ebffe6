// Foundation benchmark: octree build, full extraction and render for one volume and isovalue.
// Prints one "key value" line per figure so scripts/bench_foundation.py can put VTK's flying
// edges beside it. Each stage runs `repeats` times; the fastest run is printed (the machine is
// shared and noisy: the minimum is the most repeatable figure).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/util.h"
#include "extract/extract.h"
#include "render/renderer.h"
#include "volume/phantom.h"

namespace {

double best(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.front();
}

template <class T>
int bench(const isowall::Volume& vol, double iso, int repeats, const std::string& gl) {
    using namespace isowall;
    const auto view = vol.view<T>();
    std::vector<double> build_s, extract_s, render_s;
    MinMaxOctree<T> octree;
    for (int i = 0; i < repeats; ++i) {
        Stopwatch sw;
        octree = MinMaxOctree<T>::build(view);
        build_s.push_back(sw.seconds());
    }
    Mesh mesh;
    ExtractStats st;
    for (int i = 0; i < repeats; ++i) {
        st = {};
        Stopwatch sw;
        mesh = extract_full(view, octree, iso, &st);
        extract_s.push_back(sw.seconds());
    }
    auto renderer = make_renderer(gl);
    const int w = 1600, h = 1200;
    const Camera cam = front_full_view(vol.bounds(), float(w) / float(h));
    Image image;
    renderer->resize(w, h);
    for (int i = 0; i < repeats; ++i) {
        Stopwatch sw;
        renderer->clear();
        renderer->draw(mesh, cam.view(), cam.frustum(float(w) / float(h)).matrix());
        renderer->read_back(image);
        render_s.push_back(sw.seconds());
    }
    const double voxels = double(vol.voxel_count());
    std::printf("volume %s\n", vol.source().c_str());
    std::printf("voxels %.0f\n", voxels);
    std::printf("dims %d %d %d\n", vol.dims().x, vol.dims().y, vol.dims().z);
    std::printf("spacing %g %g %g\n", double(vol.spacing().x), double(vol.spacing().y),
                double(vol.spacing().z));
    std::printf("type %s\n", std::string(type_name(vol.type())).c_str());
    std::printf("volume_bytes %zu\n", vol.bytes().size());
    std::printf("iso %g\n", iso);
    std::printf("octree_build_s %.4f\n", best(build_s));
    std::printf("octree_voxels_per_s %.4g\n", voxels / best(build_s));
    std::printf("octree_bytes %zu\n", octree.bytes());
    std::printf("octree_overhead %.4f\n", double(octree.bytes()) / double(vol.bytes().size()));
    std::printf("extract_s %.4f\n", best(extract_s));
    std::printf("triangles %zu\n", mesh.triangle_count());
    std::printf("active_cells %zu\n", st.cells_active);
    std::printf("render_s %.4f\n", best(render_s));
    std::printf("render_size %dx%d\n", w, h);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace isowall;
    if (argc < 2) {
        std::fprintf(stderr,
                     "usage: %s VOLUME.nhdr|phantom ISO [REPEATS] [osmesa|egl] [SAVE.raw]\n",
                     argv[0]);
        return 2;
    }
    try {
        const std::string path = argv[1];
        const Volume vol = path == "phantom" ? make_phantom() : load_nrrd(path);
        const double iso = argc > 2 ? std::atof(argv[2]) : kPhantomSkinIso;
        const int repeats = argc > 3 ? std::max(1, std::atoi(argv[3])) : 3;
        const std::string gl = argc > 4 ? argv[4] : "osmesa";
        // Other tools (VTK) read the voxels from this headerless copy, so they see exactly
        // what we extract from, whatever the source format (the phantom exists only in memory).
        if (argc > 5) {
            std::FILE* f = std::fopen(argv[5], "wb");
            if (!f ||
                std::fwrite(vol.bytes().data(), 1, vol.bytes().size(), f) != vol.bytes().size())
                throw std::runtime_error(std::string(argv[5]) + ": cannot write");
            std::fclose(f);
        }
        return dispatch_voxel_type(
            vol.type(), [&](auto tag) { return bench<decltype(tag)>(vol, iso, repeats, gl); });
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_foundation: error: %s\n", e.what());
        return 1;
    }
}
