#include "master/wall_run.h"

#include <time.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "common/error.h"
#include "common/phantom.h"
#include "common/surface_extractor.h"
#include "common/util.h"
#include "common/wall.h"
#include "tile/image_io.h"
#include "tile/progressive_engine.h"

namespace isowall {
namespace {

constexpr std::uint8_t kViewVersion = 1;
constexpr std::uint8_t kResultVersion = 1;
constexpr std::uint8_t kGap = 40;  // grey of the bezel bars in the mosaic

// CPU time of the calling thread: with more ranks than cores, wall-clock time says nothing about
// parallel speed, CPU time does.
double thread_cpu_s() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

std::vector<std::byte> encode_view(const FrameView& v) {
    MessageWriter w(kViewVersion);
    const Camera& c = v.camera;
    w.put(c.eye);
    w.put(c.target);
    w.put(c.up);
    w.put(static_cast<std::int32_t>(c.projection));
    w.put(c.fovy_deg);
    w.put(c.ortho_height);
    w.put(c.near_z);
    w.put(c.far_z);
    const Frustum& f = v.frustum;
    w.put(f.left);
    w.put(f.right);
    w.put(f.bottom);
    w.put(f.top);
    w.put(f.near_z);
    w.put(f.far_z);
    w.put(static_cast<std::int32_t>(f.projection));
    w.put(static_cast<std::int32_t>(v.width));
    w.put(static_cast<std::int32_t>(v.height));
    w.put(v.iso);
    return w.bytes();
}

FrameView decode_view(std::span<const std::byte> bytes) {
    MessageReader r(bytes, kViewVersion);
    FrameView v;
    v.camera.eye = r.get<glm::vec3>();
    v.camera.target = r.get<glm::vec3>();
    v.camera.up = r.get<glm::vec3>();
    v.camera.projection = static_cast<Projection>(r.get<std::int32_t>());
    v.camera.fovy_deg = r.get<float>();
    v.camera.ortho_height = r.get<float>();
    v.camera.near_z = r.get<float>();
    v.camera.far_z = r.get<float>();
    v.frustum.left = r.get<float>();
    v.frustum.right = r.get<float>();
    v.frustum.bottom = r.get<float>();
    v.frustum.top = r.get<float>();
    v.frustum.near_z = r.get<float>();
    v.frustum.far_z = r.get<float>();
    v.frustum.projection = static_cast<Projection>(r.get<std::int32_t>());
    v.width = r.get<std::int32_t>();
    v.height = r.get<std::int32_t>();
    v.iso = r.get<double>();
    return v;
}

struct TileStats {
    std::string host;
    double cpu_s = 0, wall_s = 0, rss_mib = 0;
    std::uint64_t rays = 0, groups = 0, triangles = 0;
};

std::unique_ptr<SurfaceExtractor> open_extractor(const OpenedVolume& ov) {
    OctreeSource src;
    if (ov.file) src.volume_path = *ov.file;
    src.cache_dir = ov.cache_dir;
    return make_surface_extractor(ov.volume, src);
}

// Tile rank: one frame of its own frustum, then the image and the figures back to the master.
int run_tile(const WallOptions& o, Comm& comm, const OpenedVolume& ov) {
    auto ex = open_extractor(ov);
    auto renderer = make_renderer(o.gl);
    EngineOptions opt;
    opt.order = parse_ray_order(o.order).value_or(RayOrderKind::dynamic_grid);
    opt.propagation.max_count = o.max_count;
    ProgressiveEngine engine(*ex, *renderer, opt);
    const FrameView view = decode_view(comm.recv(kMasterRank, Tag::view));
    const double cpu0 = thread_cpu_s();
    FrameResult fr = engine.run(view);
    const double cpu = thread_cpu_s() - cpu0;
    MessageWriter w(kResultVersion);
    w.put(cpu);
    w.put(fr.elapsed_s);
    w.put(current_rss_mib());
    w.put(static_cast<std::uint64_t>(fr.rays_cast));
    w.put(static_cast<std::uint64_t>(fr.groups.size()));
    w.put(static_cast<std::uint64_t>(fr.timeline.empty() ? 0 : fr.timeline.back().triangles));
    const std::string host = comm.host();
    w.put_bytes(std::as_bytes(std::span(host)));
    w.put_bytes(std::as_bytes(std::span(fr.final_image.rgba)));
    comm.send(kMasterRank, Tag::tile_result, w.bytes());
    return 0;
}

void paste(Image& mosaic, const Image& tile, const PixelRect& r, std::vector<std::uint8_t>& count) {
    for (int y = 0; y < r.height; ++y) {
        const int my = r.y + y;
        if (my < 0 || my >= mosaic.height) continue;
        for (int x = 0; x < r.width; ++x) {
            const int mx = r.x + x;
            if (mx < 0 || mx >= mosaic.width) continue;
            const std::size_t m = static_cast<std::size_t>(my) * mosaic.width + mx;
            const std::size_t t = static_cast<std::size_t>(y) * tile.width + x;
            // Overlapping projectors both light a pixel: show the average of the two.
            const int n = ++count[m];
            for (int k = 0; k < 3; ++k) {
                const int before = n == 1 ? 0 : mosaic.rgba[4 * m + k];
                mosaic.rgba[4 * m + k] =
                    static_cast<std::uint8_t>((before * (n - 1) + tile.rgba[4 * t + k]) / n);
            }
            mosaic.rgba[4 * m + 3] = 255;
        }
    }
}

int run_master(const WallOptions& o, Comm& comm, const WallSpec& spec, const OpenedVolume& ov,
               SurfaceExtractor& ex, double iso) {
    const PixelSize vs = virtual_screen_size(spec);
    const float aspect = float(vs.width) / float(vs.height);
    const Camera cam = fit_depth_range(front_full_view(ov.volume.bounds(), aspect), ov.volume.bounds());
    const Frustum wall_frustum = cam.frustum(aspect);
    std::printf("wall: %s: %dx%d tiles of %dx%d, virtual screen %dx%d, %d tile ranks\n", o.wall.c_str(),
                spec.columns, spec.rows, spec.tile_width_px, spec.tile_height_px, vs.width, vs.height,
                comm.size() - 1);
    for (int rank = 1; rank < comm.size(); ++rank) {
        const int tile = tile_of_rank(spec, rank);
        const PixelRect r = tile_rect(spec, tile);
        const FrameView view{cam, tile_frustum(wall_frustum, spec, tile), r.width, r.height, iso};
        std::printf("  rank %2d -> tile %2d (column %d, row %d) viewport x=%d y=%d %dx%d\n", rank, tile,
                    tile % spec.columns, tile / spec.columns, r.x, r.y, r.width, r.height);
        comm.send(rank, Tag::view, encode_view(view));
    }
    std::fflush(stdout);
    (void)ex;

    Image mosaic;
    mosaic.resize(vs.width, vs.height);
    for (std::size_t i = 0; i < mosaic.pixel_count(); ++i) {
        for (int k = 0; k < 3; ++k) mosaic.rgba[4 * i + k] = kGap;
        mosaic.rgba[4 * i + 3] = 255;
    }
    std::vector<std::uint8_t> count(mosaic.pixel_count(), 0);
    std::vector<TileStats> stats(static_cast<std::size_t>(comm.size()));
    for (int rank = 1; rank < comm.size(); ++rank) {
        const auto bytes = comm.recv(rank, Tag::tile_result);
        MessageReader r(bytes, kResultVersion);
        TileStats& s = stats[static_cast<std::size_t>(rank)];
        s.cpu_s = r.get<double>();
        s.wall_s = r.get<double>();
        s.rss_mib = r.get<double>();
        s.rays = r.get<std::uint64_t>();
        s.groups = r.get<std::uint64_t>();
        s.triangles = r.get<std::uint64_t>();
        const auto host = r.get_bytes();
        s.host.assign(reinterpret_cast<const char*>(host.data()), host.size());
        const auto rgba = r.get_bytes();
        const int tile = tile_of_rank(spec, rank);
        const PixelRect rect = tile_rect(spec, tile);
        Image img;
        img.resize(rect.width, rect.height);
        if (rgba.size() != img.rgba.size())
            throw std::runtime_error("rank " + std::to_string(rank) + ": tile image of the wrong size");
        std::memcpy(img.rgba.data(), rgba.data(), rgba.size());
        paste(mosaic, img, rect, count);
        if (!o.tiles_out.empty())
            write_image(std::filesystem::path(o.tiles_out) / ("tile_" + std::to_string(tile) + ".png"), img);
    }
    write_image(o.out, mosaic);
    std::printf("per rank (CPU time of the frame thread; makespan = the slowest tile):\n");
    std::printf("  %4s %-16s %5s %9s %9s %10s %8s %10s %9s\n", "rank", "host", "tile", "cpu s", "wall s",
                "rays", "groups", "triangles", "RSS MiB");
    double makespan = 0, total = 0;
    for (int rank = 1; rank < comm.size(); ++rank) {
        const TileStats& s = stats[static_cast<std::size_t>(rank)];
        std::printf("  %4d %-16s %5d %9.3f %9.3f %10llu %8llu %10llu %9.1f\n", rank, s.host.c_str(),
                    tile_of_rank(spec, rank), s.cpu_s, s.wall_s, (unsigned long long)s.rays,
                    (unsigned long long)s.groups, (unsigned long long)s.triangles, s.rss_mib);
        makespan = std::max(makespan, s.cpu_s);
        total += s.cpu_s;
    }
    std::printf("makespan %.3f s (CPU), total %.3f s, balance %.2f (mean/max)\n", makespan, total,
                comm.size() > 1 ? total / double(comm.size() - 1) / std::max(makespan, 1e-9) : 1.0);
    std::printf("wrote %s\n", o.out.c_str());
    return 0;
}

}  // namespace

int run_wall(const WallOptions& o, Comm& comm) {
    // Every rank reads the wall file (it is small): a bad file is the same error everywhere, and
    // every rank can check the rank count against it without waiting for the master.
    WallSpec spec;
    try {
        spec = load_wall(o.wall);
    } catch (const std::exception& e) {
        if (comm.is_master()) std::fprintf(stderr, "isowall: error: %s\n", e.what());
        return 1;
    }
    if (comm.size() != rank_count(spec)) {
        std::fprintf(stderr,
                     "isowall: error: %s: tiles: the wall has %d tile(s), so it needs mpirun -np %d "
                     "(one master + one rank per tile); this job has %d ranks (rank %d)\n",
                     o.wall.c_str(), rank_count(spec) - 1, rank_count(spec), comm.size(), comm.rank());
        return 1;
    }
    // The master loads first and writes the octree cache; the tile ranks then map the same files,
    // so the machine holds one copy of the volume and the octree.
    std::optional<OpenedVolume> ov;
    std::unique_ptr<SurfaceExtractor> ex;
    double iso = 0;
    if (comm.is_master()) {
        try {
            ov.emplace(open_volume(o.volume));
            ex = open_extractor(*ov);
            iso = o.iso.value_or(kPhantomSkinIso);
            if (!o.iso && ov->file)
                throw InputError(ov->file->string(), "--iso", "an isovalue is required (see `isowall info`)");
            if (iso < ex->value_min() || iso > ex->value_max())
                throw InputError(ov->file ? ov->file->string() : "phantom", "--iso",
                                 "isovalue " + std::to_string(iso) + " is outside the volume's value range");
            auto dir = std::filesystem::path(o.out).parent_path();
            if (!dir.empty() && !std::filesystem::is_directory(dir))
                throw InputError(o.out, "--out", "folder " + dir.string() + " does not exist");
        } catch (const std::exception& e) {
            std::fprintf(stderr, "isowall: error: %s\n", e.what());
            comm.abort(1);  // the tile ranks wait at the barrier below
        }
    }
    comm.barrier();
    if (comm.is_master()) return run_master(o, comm, spec, *ov, *ex, iso);
    try {
        OpenedVolume mine = open_volume(o.volume, /*quiet=*/true);
        return run_tile(o, comm, mine);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "isowall: error: rank %d: %s\n", comm.rank(), e.what());
        comm.abort(1);
    }
    return 1;
}

}  // namespace isowall
