// Renderer benchmark: how fast a back end draws an isosurface mesh, whole and in engine-sized
// groups, and reads a frame back. Run here on Mesa's llvmpipe (OSMesa, EGL) and, on a GPU node,
// on the vendor's EGL driver; the figures go into the README's renderer table.
//
//   isowall_bench_render MESH.ply [--gl osmesa|egl] [--size 1600x1200] [--reps 7] [--group 2000]
//
// MESH.ply is what `isowall extract` writes (binary little-endian, x y z nx ny nz, triangles).
// The view is the front full view of the mesh's bounds, as `isowall render` uses.
#include <EGL/egl.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/camera.h"
#include "render/backends.h"
#include "render/renderer.h"

namespace isowall {

#ifdef ISOWALL_BENCH_EGL_ONLY
// The GPU build links the EGL back end alone (no OSMesa, no LLVM to carry to the GPU node).
std::unique_ptr<Renderer> make_osmesa_renderer() {
    throw RendererError("osmesa", "not in this EGL-only build");
}
#endif

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The PLY that write_ply writes, and nothing else: one clear error for anything other.
Mesh read_mesh(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path + ": cannot open");
    std::string line;
    std::size_t vertices = 0, faces = 0;
    while (std::getline(in, line) && line != "end_header") {
        std::istringstream words(line);
        std::string w, what;
        words >> w >> what;
        if (w == "format" && what != "binary_little_endian")
            throw std::runtime_error(path + ": format: expected binary_little_endian");
        if (w == "element" && what == "vertex") words >> vertices;
        if (w == "element" && what == "face") words >> faces;
    }
    if (line != "end_header" || vertices == 0 || faces == 0)
        throw std::runtime_error(path + ": header: expected vertex and face elements");
    Mesh m;
    std::vector<float> v(vertices * 6);
    in.read(reinterpret_cast<char*>(v.data()),
            static_cast<std::streamsize>(v.size() * sizeof(float)));
    for (std::size_t i = 0; i < vertices; ++i) {
        m.positions.emplace_back(v[6 * i], v[6 * i + 1], v[6 * i + 2]);
        m.normals.emplace_back(v[6 * i + 3], v[6 * i + 4], v[6 * i + 5]);
    }
    std::vector<char> f(faces * 13);
    in.read(f.data(), static_cast<std::streamsize>(f.size()));
    if (!in) throw std::runtime_error(path + ": data: shorter than the header says");
    for (std::size_t i = 0; i < faces; ++i) {
        std::int32_t idx[3];
        std::memcpy(idx, f.data() + 13 * i + 1, sizeof(idx));
        for (std::int32_t k : idx) m.indices.push_back(static_cast<std::uint32_t>(k));
    }
    return m;
}

// Engine-sized groups: consecutive runs of `group` triangles, each an indexed face set of its own
// vertices (as a propagation pass makes), drawn with its own call.
std::vector<Mesh> split(const Mesh& m, std::size_t group) {
    std::vector<Mesh> out;
    std::vector<std::uint32_t> local(m.vertex_count());
    std::vector<std::size_t> stamp(m.vertex_count(), 0);
    for (std::size_t t = 0; t < m.triangle_count(); t += group) {
        Mesh g;
        const std::size_t end = std::min(m.triangle_count(), t + group);
        for (std::size_t i = 3 * t; i < 3 * end; ++i) {
            const std::uint32_t v = m.indices[i];
            if (stamp[v] != t + 1) {
                stamp[v] = t + 1;
                local[v] = static_cast<std::uint32_t>(g.positions.size());
                g.positions.push_back(m.positions[v]);
                g.normals.push_back(m.normals[v]);
            }
            g.indices.push_back(local[v]);
        }
        out.push_back(std::move(g));
    }
    return out;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

void print_driver() {
    const EGLDisplay d = eglGetCurrentDisplay();
    if (d == EGL_NO_DISPLAY) return;
    using GetString = const unsigned char* (*)(unsigned);
    const auto get_string = reinterpret_cast<GetString>(eglGetProcAddress("glGetString"));
    const unsigned kRenderer = 0x1F01, kVersion = 0x1F02;
    std::printf("driver: EGL %s; GL %s, %s\n", eglQueryString(d, EGL_VENDOR),
                get_string ? reinterpret_cast<const char*>(get_string(kRenderer)) : "?",
                get_string ? reinterpret_cast<const char*>(get_string(kVersion)) : "?");
}

int run(int argc, char** argv) {
    if (argc < 2)
        throw std::runtime_error(
            "usage: isowall_bench_render MESH.ply [--gl osmesa|egl] "
            "[--size WxH] [--reps N] [--group T]");
    std::string gl = "egl";
    int width = 1600, height = 1200, reps = 7;
    std::size_t group = 2000;
    for (int i = 2; i + 1 < argc; i += 2) {
        const std::string k = argv[i], v = argv[i + 1];
        if (k == "--gl")
            gl = v;
        else if (k == "--size" && std::sscanf(v.c_str(), "%dx%d", &width, &height) == 2) {
        } else if (k == "--reps")
            reps = std::max(1, std::atoi(v.c_str()));
        else if (k == "--group")
            group = std::max(1, std::atoi(v.c_str()));
        else
            throw std::runtime_error("option " + k + ": unknown or bad value " + v);
    }
    const Mesh mesh = read_mesh(argv[1]);
    const auto r = make_renderer(gl);
    r->resize(width, height);
    if (gl == "egl") print_driver();
    const Camera cam = fit_depth_range(front_full_view(mesh.bounds(), float(width) / float(height)),
                                       mesh.bounds());
    const glm::mat4 view = cam.view(), proj = cam.frustum(float(width) / float(height)).matrix();
    const std::vector<Mesh> groups = split(mesh, group);
    std::vector<double> whole, grouped, readback;
    Image img;
    for (int rep = 0; rep <= reps; ++rep) {  // rep 0 warms shaders and buffers up
        r->clear();
        r->finish();
        auto t0 = Clock::now();
        r->draw(mesh, view, proj);
        r->finish();
        const double w = seconds_since(t0);
        r->clear();
        r->finish();
        t0 = Clock::now();
        for (const Mesh& g : groups) r->draw(g, view, proj);
        r->finish();
        const double g = seconds_since(t0);
        t0 = Clock::now();
        r->read_back(img);
        const double rb = seconds_since(t0);
        if (rep == 0) continue;
        whole.push_back(w);
        grouped.push_back(g);
        readback.push_back(rb);
    }
    std::size_t covered = 0;
    for (float d : img.depth) covered += d < 1.0f;
    const double tri = double(mesh.triangle_count());
    std::printf(
        "%s %dx%d, %zu triangles, %zu groups of %zu, %.1f%% of pixels covered; median of %d:\n",
        gl.c_str(), width, height, mesh.triangle_count(), groups.size(), group,
        100.0 * double(covered) / double(img.pixel_count()), reps);
    std::printf("  whole mesh   %8.4f s  (%6.1f M triangles/s)\n", median(whole),
                tri / median(whole) / 1e6);
    std::printf("  in groups    %8.4f s  (%6.1f M triangles/s)\n", median(grouped),
                tri / median(grouped) / 1e6);
    std::printf("  read-back    %8.4f s  (colour and depth)\n", median(readback));
    return 0;
}

}  // namespace
}  // namespace isowall

int main(int argc, char** argv) {
    try {
        return isowall::run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "isowall_bench_render: error: %s\n", e.what());
        return 1;
    }
}
