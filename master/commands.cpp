#include "master/commands.h"

#include <cstdio>
#include <filesystem>

#include "common/camera.h"
#include "common/error.h"
#include "common/extract.h"
#include "common/phantom.h"
#include "common/ply.h"
#include "common/util.h"
#include "tile/image_io.h"
#include "tile/renderer.h"

namespace isowall {
namespace {

// One line per stage, then a summary line that scripts can grep for.
struct Timings {
    double load = 0, octree = 0, extract = 0, render = 0, write = 0;
    void print(std::size_t triangles) const {
        std::printf("timing: load %.3f s | octree %.3f s | extract %.3f s | render %.3f s | write %.3f s"
                    " | triangles %zu | peak RSS %.1f MiB\n",
                    load, octree, extract, render, write, triangles, peak_rss_mib());
    }
};

template <class T>
MinMaxOctree<T> prepare_octree(const OpenedVolume& ov, Timings& t) {
    OctreeSource src;
    if (ov.file) src.volume_path = *ov.file;
    src.cache_dir = ov.cache_dir;
    OctreeStats st;
    Stopwatch sw;
    auto octree = MinMaxOctree<T>::load_or_build(ov.volume.view<T>(), src, &st);
    t.octree = sw.seconds();
    const double share = double(octree.bytes()) / double(ov.volume.bytes().size());
    if (st.from_cache) {
        std::printf("octree: mapped %s  (%.3f s)\n", st.cache_file.c_str(), t.octree);
    } else {
        std::printf("octree: built in %.3f s (%.0f M voxels/s)%s%s\n", st.build_s,
                    double(ov.volume.voxel_count()) / std::max(st.build_s, 1e-9) / 1e6,
                    st.cache_file.empty() ? "" : ", cached to ", st.cache_file.c_str());
    }
    if (!st.cache_note.empty()) std::printf("octree: note: %s\n", st.cache_note.c_str());
    std::printf("octree: %d levels, depth %d, %zu nodes, %.2f MiB = %.2f%% of the volume bytes, values [%g, %g]\n",
                octree.level_count(), octree.shape().depth(), octree.shape().node_count,
                double(octree.bytes()) / (1024.0 * 1024.0), 100.0 * share,
                double(octree.value_min()), double(octree.value_max()));
    return octree;
}

double checked_iso(const std::optional<double>& iso, const OpenedVolume& ov, double lo, double hi) {
    const std::string where = ov.file ? ov.file->string() : std::string("phantom");
    if (!iso) {
        if (!ov.file) return kPhantomSkinIso;
        throw InputError(where, "--iso", "an isovalue is required (see `isowall info`)");
    }
    if (!std::isfinite(*iso) || *iso < lo || *iso > hi) {
        char msg[160];
        std::snprintf(msg, sizeof(msg), "isovalue %g is outside the volume's value range [%g, %g]",
                      *iso, lo, hi);
        throw InputError(where, "--iso", msg);
    }
    return *iso;
}

template <class T>
Mesh extract_timed(const VolumeView<T>& v, const MinMaxOctree<T>& octree, double iso, Timings& t) {
    ExtractStats es;
    Stopwatch sw;
    Mesh mesh = extract_full(v, octree, iso, &es);
    t.extract = sw.seconds();
    std::printf("extract: iso %g: %zu triangles, %zu vertices, %zu active cells, %zu octree nodes "
                "visited, %zu leaf bricks scanned (%.3f s)\n",
                iso, mesh.triangle_count(), mesh.vertex_count(), es.cells_active, es.nodes_visited,
                es.leaves_active, t.extract);
    return mesh;
}

// Output goes through a temporary name, so nothing half-written is left; check the folder first
// so a typo fails before the expensive work.
void check_output_path(const std::string& path, const char* option) {
    if (path.empty()) throw InputError(option, "path", "an output file is required");
    auto dir = std::filesystem::path(path).parent_path();
    if (!dir.empty() && !std::filesystem::is_directory(dir))
        throw InputError(path, option, "folder " + dir.string() + " does not exist");
}

}  // namespace

int run_info(const InfoOptions& o) {
    Timings t;
    OpenedVolume ov = open_volume(o.volume);
    t.load = ov.load_s;
    dispatch_voxel_type(ov.volume.type(), [&](auto tag) {
        using T = decltype(tag);
        prepare_octree<T>(ov, t);
    });
    const Box3 b = ov.volume.bounds();
    std::printf("bounds: (%g, %g, %g) - (%g, %g, %g) object units\n", double(b.min.x), double(b.min.y),
                double(b.min.z), double(b.max.x), double(b.max.y), double(b.max.z));
    if (!ov.file)
        std::printf("suggested isovalues: skin %g, bone %g\n", kPhantomSkinIso, kPhantomBoneIso);
    return 0;
}

int run_extract(const ExtractOptions& o) {
    check_output_path(o.out, "--out");
    Timings t;
    OpenedVolume ov = open_volume(o.volume);
    t.load = ov.load_s;
    std::size_t triangles = 0;
    dispatch_voxel_type(ov.volume.type(), [&](auto tag) {
        using T = decltype(tag);
        auto octree = prepare_octree<T>(ov, t);
        const double iso = checked_iso(o.iso, ov, double(octree.value_min()), double(octree.value_max()));
        Mesh mesh = extract_timed(ov.volume.view<T>(), octree, iso, t);
        triangles = mesh.triangle_count();
        Stopwatch sw;
        write_ply(o.out, mesh);
        t.write = sw.seconds();
        std::printf("wrote %s\n", o.out.c_str());
    });
    t.print(triangles);
    return 0;
}

int run_render(const RenderOptions& o) {
    const auto size = parse_size(o.size);
    if (!size)
        throw InputError("--size", "value", "expected WIDTHxHEIGHT with positive integers, got \"" + o.size + "\"");
    check_output_path(o.out, "--out");
    if (!o.depth_out.empty()) check_output_path(o.depth_out, "--depth-out");
    Timings t;
    // Create the GL context first: a missing driver should fail before the volume is read.
    auto renderer = make_renderer(o.gl);
    OpenedVolume ov = open_volume(o.volume);
    t.load = ov.load_s;
    std::size_t triangles = 0;
    dispatch_voxel_type(ov.volume.type(), [&](auto tag) {
        using T = decltype(tag);
        auto octree = prepare_octree<T>(ov, t);
        const double iso = checked_iso(o.iso, ov, double(octree.value_min()), double(octree.value_max()));
        Mesh mesh = extract_timed(ov.volume.view<T>(), octree, iso, t);
        triangles = mesh.triangle_count();

        const float aspect = float(size->x) / float(size->y);
        const Projection proj = o.projection == "orthographic" ? Projection::orthographic : Projection::perspective;
        Camera cam = front_full_view(ov.volume.bounds(), aspect, proj);
        if (o.orbit.size() == 2) cam = orbit(cam, o.orbit[0], o.orbit[1]);
        cam = fit_depth_range(zoom(cam, o.zoom), ov.volume.bounds());

        Stopwatch sw;
        Image image;
        renderer->resize(size->x, size->y);
        renderer->clear();
        renderer->draw(mesh, cam.view(), cam.frustum(aspect).matrix());
        renderer->read_back(image);
        t.render = sw.seconds();
        std::size_t covered = 0;
        for (float d : image.depth) covered += d < 1.0f;
        std::printf("render: %s %dx%d, %.1f%% of pixels covered (%.3f s)\n",
                    std::string(renderer->name()).c_str(), size->x, size->y,
                    100.0 * double(covered) / double(image.pixel_count()), t.render);
        sw.restart();
        write_image(o.out, image);
        if (!o.depth_out.empty()) write_depth(o.depth_out, image);
        t.write = sw.seconds();
        std::printf("wrote %s%s%s\n", o.out.c_str(), o.depth_out.empty() ? "" : " and ",
                    o.depth_out.c_str());
    });
    t.print(triangles);
    return 0;
}

}  // namespace isowall
