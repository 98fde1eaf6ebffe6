#include "master/wall_run.h"

#include <algorithm>
#include <cstdlib>
#include <cstdio>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "common/core/error.h"
#include "common/volume/phantom.h"
#include "common/wall/script.h"
#include "common/extract/surface_extractor.h"
#include "common/progressive/trace.h"
#include "common/core/util.h"
#include "common/wall/wall.h"
#include "common/io/image_io.h"
#include "tile/progressive_engine.h"

namespace isowall {
namespace {

constexpr std::uint8_t kViewVersion = 1;
constexpr std::uint8_t kResultVersion = 1;
constexpr std::uint8_t kGap = 40;  // grey of the bezel bars in the mosaic

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
    std::uint64_t rays = 0, groups = 0, triangles = 0, frames = 0, interrupted = 0;
    std::vector<TraceSpan> spans;
};

std::unique_ptr<SurfaceExtractor> open_extractor(const OpenedVolume& ov) {
    OctreeSource src;
    if (ov.file) src.volume_path = *ov.file;
    src.cache_dir = ov.cache_dir;
    return make_surface_extractor(ov.volume, src);
}

void send_image(Comm& comm, Tag tag, std::uint64_t generation, Renderer& renderer) {
    Image img;
    renderer.finish();
    renderer.read_back(img);
    MessageWriter w(kResultVersion);
    w.put(generation);
    w.put_bytes(std::as_bytes(std::span(img.rgba)));
    comm.send(kMasterRank, tag, w.bytes());
}

// Tile rank: frames of its own frustum until the master says quit. A new view (or quit) arriving
// mid-frame interrupts the frame at once; a snapshot request is answered from the frame being
// built, and progress goes to the master at every timeline sample.
int run_tile(const WallOptions& o, Comm& comm, const OpenedVolume& ov) {
    {
        const std::string host = comm.host();
        comm.send(kMasterRank, Tag::hello, std::as_bytes(std::span(host)));
    }
    // Test hook for fault handling: ISOWALL_TEST_FAULT=hang:R or exit:R makes tile rank R stop
    // answering, or die, after its first view arrives.
    std::string fault;
    if (const char* f = std::getenv("ISOWALL_TEST_FAULT")) {
        const std::string spec = f;
        const auto colon = spec.find(':');
        if (colon != std::string::npos && std::atoi(spec.c_str() + colon + 1) == comm.rank())
            fault = spec.substr(0, colon);
    }
    auto ex = open_extractor(ov);
    auto renderer = make_renderer(o.gl);
    EngineOptions opt = to_engine_options(o.engine);
    opt.progress_interval_s = 0.05;
    TraceRecorder trace;
    opt.trace = &trace;
    ProgressiveEngine engine(*ex, *renderer, opt);

    std::optional<std::pair<Tag, std::vector<std::byte>>> pending;
    std::uint64_t generation = 0, rays = 0, groups = 0, triangles = 0, frames = 0, interrupted_frames = 0;
    double cpu_s = 0, frame_s = 0;
    auto send_progress = [&](std::uint64_t frame_rays, bool done) {
        const Stage left = trace.switch_to(Stage::comm);
        MessageWriter w(kResultVersion);
        w.put(generation);
        w.put(frame_rays);
        w.put(static_cast<std::uint8_t>(done));
        comm.send(kMasterRank, Tag::progress, w.bytes());
        trace.switch_to(left);
    };
    for (;;) {
        trace.switch_to(Stage::idle);
        auto [tag, bytes] = pending ? std::move(*pending) : comm.recv_any(kMasterRank);
        pending.reset();
        trace.switch_to(Stage::comm);
        if (tag == Tag::snapshot) {
            send_image(comm, Tag::image, generation, *renderer);
        } else if (tag == Tag::view) {
            if (fault == "hang") std::this_thread::sleep_for(std::chrono::hours(1));
            if (fault == "exit") std::_Exit(3);
            MessageReader r(bytes, kViewVersion);
            generation = r.get<std::uint64_t>();
            const FrameView view = decode_view(r.get_bytes());
            std::size_t polls = 0;
            // Sticky: once a new view or quit is pending, every later poll says stop too (the engine
            // polls again after a propagation pass it cut short).
            auto interrupted = [&] {
                if (pending) return true;
                if (++polls % 32 != 0) return false;
                while (auto t = comm.probe(kMasterRank)) {
                    if (*t == Tag::snapshot) {
                        const Stage left = trace.switch_to(Stage::comm);
                        comm.recv(kMasterRank, Tag::snapshot);
                        send_image(comm, Tag::image, generation, *renderer);
                        trace.switch_to(left);
                        continue;
                    }
                    pending = comm.recv_any(kMasterRank);  // a new view or quit: stop this frame
                    return true;
                }
                return false;
            };
            const double cpu0 = thread_cpu_seconds();
            FrameResult fr = engine.run(view, interrupted,
                                        [&](const TimelineSample& s) { send_progress(s.rays, false); });
            cpu_s += thread_cpu_seconds() - cpu0;
            frame_s += fr.elapsed_s;
            ++frames;
            rays += fr.rays_cast;
            groups += fr.groups.size();
            triangles = fr.timeline.empty() ? 0 : fr.timeline.back().triangles;
            if (fr.completed) {
                send_progress(fr.rays_cast, true);
            } else {
                ++interrupted_frames;
            }
        } else if (tag == Tag::quit) {
            MessageWriter w(kResultVersion);
            w.put(cpu_s);
            w.put(frame_s);
            w.put(current_rss_mib());
            w.put(rays);
            w.put(groups);
            w.put(triangles);
            w.put(frames);
            w.put(interrupted_frames);
            const std::string host = comm.host();
            w.put_bytes(std::as_bytes(std::span(host)));
            trace.close();
            w.put(static_cast<std::uint64_t>(trace.spans().size()));
            for (const TraceSpan& sp : trace.spans()) {
                w.put(sp.stage);
                w.put(sp.start_s);
                w.put(sp.wall_s);
                w.put(sp.cpu_s);
            }
            comm.send(kMasterRank, Tag::tile_result, w.bytes());
            send_image(comm, Tag::image, generation, *renderer);
            return 0;
        }
    }
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

// The master's side of a wall run: views out, progress and images in.
class WallMaster {
public:
    WallMaster(const WallOptions& o, Comm& comm, const WallSpec& spec, const Box3& bounds, double iso,
               double value_min, double value_max)
        : o_(o), comm_(comm), spec_(spec), bounds_(bounds), iso_(iso), lo_(value_min), hi_(value_max) {
        const PixelSize vs = virtual_screen_size(spec);
        aspect_ = float(vs.width) / float(vs.height);
        camera_ = front_full_view(bounds, aspect_);
        progress_.resize(static_cast<std::size_t>(comm.size()));
    }

    // Waits for every tile's hello (its host), then prints the rank -> host -> tile map.
    void print_map() {
        std::vector<std::string> hosts(static_cast<std::size_t>(comm_.size()));
        for (int got = 0; got < comm_.size() - 1;) {
            int from = 0;
            auto [tag, bytes] = receive(&from);
            if (tag != Tag::hello) continue;
            hosts[static_cast<std::size_t>(from)].assign(reinterpret_cast<const char*>(bytes.data()), bytes.size());
            ++got;
        }
        const PixelSize vs = virtual_screen_size(spec_);
        std::printf("wall: %s: %dx%d tiles of %dx%d, virtual screen %dx%d, %d tile ranks, master on %s\n",
                    o_.wall.c_str(), spec_.columns, spec_.rows, spec_.tile_width_px, spec_.tile_height_px,
                    vs.width, vs.height, comm_.size() - 1, comm_.host().c_str());
        for (int rank = 1; rank < comm_.size(); ++rank) {
            const int tile = tile_of_rank(spec_, rank);
            const PixelRect r = tile_rect(spec_, tile);
            std::printf("  rank %2d on %-12s -> tile %2d (column %d, row %d) viewport x=%d y=%d %dx%d\n", rank,
                        hosts[static_cast<std::size_t>(rank)].c_str(), tile, tile % spec_.columns,
                        tile / spec_.columns, r.x, r.y, r.width, r.height);
        }
        std::fflush(stdout);
    }

    // A new frame on every tile: bumps the generation, so progress of older frames is ignored.
    void send_views() {
        const Stage left = trace_.switch_to(Stage::comm);
        ++generation_;
        const Camera cam = fit_depth_range(camera_, bounds_);
        const Frustum wall = cam.frustum(aspect_);
        for (int rank = 1; rank < comm_.size(); ++rank) {
            const int tile = tile_of_rank(spec_, rank);
            const PixelRect r = tile_rect(spec_, tile);
            MessageWriter w(kViewVersion);
            w.put(generation_);
            w.put_bytes(encode_view({cam, tile_frustum(wall, spec_, tile), r.width, r.height, iso_}));
            comm_.send(rank, Tag::view, w.bytes());
            progress_[static_cast<std::size_t>(rank)] = {};
        }
        frame_start_ = Stopwatch();
        trace_.switch_to(left);
    }

    // Runs one command; throws InputError for a command that cannot apply (isovalue out of range).
    bool execute(const ScriptCommand& cmd, const std::string& where) {
        if (const auto* c = std::get_if<OrbitCmd>(&cmd)) {
            camera_ = orbit(camera_, c->yaw_deg, c->pitch_deg);
        } else if (const auto* c = std::get_if<LookAtCmd>(&cmd)) {
            camera_.eye = c->eye;
            camera_.target = c->target;
        } else if (const auto* c = std::get_if<ZoomCmd>(&cmd)) {
            camera_ = zoom(camera_, c->factor);
        } else if (const auto* c = std::get_if<IsoCmd>(&cmd)) {
            if (c->iso < lo_ || c->iso > hi_) {
                char msg[160];
                std::snprintf(msg, sizeof(msg), "isovalue %g is outside the volume's value range [%g, %g]",
                              c->iso, lo_, hi_);
                throw InputError(where, "iso", msg);
            }
            iso_ = c->iso;
        } else if (const auto* c = std::get_if<WaitCmd>(&cmd)) {
            wait(*c);
            return true;
        } else if (const auto* c = std::get_if<SnapshotCmd>(&cmd)) {
            const auto dir = std::filesystem::path(o_.out).parent_path();
            const auto path = dir / (c->name + ".png");
            write_image(path, gather_images(Tag::snapshot));
            std::printf("snapshot: %s (frame %llu, %.3f s into it, %llu rays)\n", path.c_str(),
                        (unsigned long long)generation_, frame_start_.seconds(),
                        (unsigned long long)total_rays());
            return true;
        } else if (std::holds_alternative<QuitCmd>(cmd)) {
            return false;
        }
        send_views();
        return true;
    }

    // Quit: every tile's figures and final image; the mosaic and the per-rank table.
    int finish() {
        for (int rank = 1; rank < comm_.size(); ++rank) comm_.send(rank, Tag::quit, {});
        std::vector<TileStats> stats(static_cast<std::size_t>(comm_.size()));
        Mosaic mosaic = empty_mosaic();
        for (int results = 0, images = 0; results < comm_.size() - 1 || images < comm_.size() - 1;) {
            int from = 0;
            auto [tag, bytes] = receive(&from);
            if (tag == Tag::image) {
                paste_image(mosaic, bytes, from);
                ++images;
                continue;
            }
            if (tag != Tag::tile_result) {
                absorb(tag, bytes, from);
                continue;
            }
            MessageReader r(bytes, kResultVersion);
            TileStats& s = stats[static_cast<std::size_t>(from)];
            s.cpu_s = r.get<double>();
            s.wall_s = r.get<double>();
            s.rss_mib = r.get<double>();
            s.rays = r.get<std::uint64_t>();
            s.groups = r.get<std::uint64_t>();
            s.triangles = r.get<std::uint64_t>();
            s.frames = r.get<std::uint64_t>();
            s.interrupted = r.get<std::uint64_t>();
            const auto host = r.get_bytes();
            s.host.assign(reinterpret_cast<const char*>(host.data()), host.size());
            s.spans.resize(static_cast<std::size_t>(r.get<std::uint64_t>()));
            for (TraceSpan& sp : s.spans) {
                sp.stage = r.get<std::uint8_t>();
                sp.start_s = r.get<double>();
                sp.wall_s = r.get<double>();
                sp.cpu_s = r.get<double>();
            }
            ++results;
        }
        trace_.switch_to(Stage::compose);
        write_image(o_.out, mosaic.image);
        std::printf("per rank (CPU seconds of each tile's frame thread, all frames; makespan = the largest):\n");
        std::printf("  %4s %-12s %4s %8s %8s %7s %6s %10s %7s %10s %8s\n", "rank", "host", "tile", "cpu s",
                    "frame s", "frames", "intr", "rays", "groups", "triangles", "RSS MiB");
        double makespan = 0, total = 0;
        for (int rank = 1; rank < comm_.size(); ++rank) {
            const TileStats& s = stats[static_cast<std::size_t>(rank)];
            std::printf("  %4d %-12s %4d %8.3f %8.3f %7llu %6llu %10llu %7llu %10llu %8.1f\n", rank,
                        s.host.c_str(), tile_of_rank(spec_, rank), s.cpu_s, s.wall_s,
                        (unsigned long long)s.frames, (unsigned long long)s.interrupted,
                        (unsigned long long)s.rays, (unsigned long long)s.groups,
                        (unsigned long long)s.triangles, s.rss_mib);
            makespan = std::max(makespan, s.cpu_s);
            total += s.cpu_s;
        }
        std::printf("makespan %.3f s (CPU), total %.3f s, balance %.2f (mean/max)\n", makespan, total,
                    total / double(comm_.size() - 1) / std::max(makespan, 1e-9));
        trace_.close();
        print_stage_table(stats);
        if (!o_.trace.empty()) {
            std::vector<RankTrace> ranks{{kMasterRank, "master", trace_.spans()}};
            for (int rank = 1; rank < comm_.size(); ++rank)
                ranks.push_back({rank, "tile " + std::to_string(tile_of_rank(spec_, rank)),
                                 stats[static_cast<std::size_t>(rank)].spans});
            write_chrome_trace(o_.trace + ".json", ranks);
            write_trace_csv(o_.trace + ".csv", ranks);
            std::printf("wrote %s.json (Chrome trace: open in Perfetto) and %s.csv\n", o_.trace.c_str(),
                        o_.trace.c_str());
        }
        std::printf("wrote %s\n", o_.out.c_str());
        return 0;
    }

private:
    void print_stage_table(const std::vector<TileStats>& stats) const {
        std::printf("CPU seconds by stage (thread CPU time; propagation includes marching cubes):\n  %4s",
                    "rank");
        for (const char* name : kTraceStages) std::printf(" %12s", name);
        std::printf("\n");
        auto row = [&](int rank, const std::vector<TraceSpan>& spans) {
            std::vector<double> sum(std::size(kTraceStages), 0.0);
            for (const TraceSpan& sp : spans) sum[sp.stage] += sp.cpu_s;
            std::printf("  %4d", rank);
            for (double v : sum) std::printf(" %12.3f", v);
            std::printf("\n");
        };
        row(kMasterRank, trace_.spans());
        for (int rank = 1; rank < comm_.size(); ++rank) row(rank, stats[static_cast<std::size_t>(rank)].spans);
    }

    struct Progress {
        std::uint64_t rays = 0;
        bool done = false;
    };

    // The next message from any tile; a tile silent for --timeout seconds ends the job.
    std::pair<Tag, std::vector<std::byte>> receive(int* from) {
        const Stage left = trace_.switch_to(Stage::idle);
        struct Restore {
            TraceRecorder& t;
            Stage s;
            ~Restore() { t.switch_to(s); }
        } restore{trace_, left};
        Stopwatch waited;
        for (;;) {
            for (int rank = 1; rank < comm_.size(); ++rank)
                if (comm_.probe(rank)) return comm_.recv_any(rank, from);
            if (waited.seconds() > o_.timeout_s) {
                std::fprintf(stderr, "isowall: error: no tile rank has answered for %g s (waiting on %s); "
                             "ending the job\n", o_.timeout_s, waiting_on().c_str());
                comm_.abort(2);
            }
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
    }

    std::string waiting_on() const {
        std::string list;
        for (int rank = 1; rank < comm_.size(); ++rank)
            if (!progress_[static_cast<std::size_t>(rank)].done)
                list += (list.empty() ? "" : ", ") + std::string("rank ") + std::to_string(rank) + " (tile " +
                        std::to_string(tile_of_rank(spec_, rank)) + ")";
        return list.empty() ? "all tiles" : list;
    }

    void absorb(Tag tag, const std::vector<std::byte>& bytes, int from) {
        if (tag != Tag::progress) return;  // a stale image from an abandoned request
        MessageReader r(bytes, kResultVersion);
        const auto gen = r.get<std::uint64_t>();
        const auto rays = r.get<std::uint64_t>();
        const bool done = r.get<std::uint8_t>() != 0;
        if (gen != generation_) return;  // progress of a frame that was interrupted
        Progress& p = progress_[static_cast<std::size_t>(from)];
        p.rays = std::max(p.rays, rays);
        p.done = p.done || done;
    }

    std::uint64_t total_rays() const {
        std::uint64_t n = 0;
        for (const Progress& p : progress_) n += p.rays;
        return n;
    }
    bool all_done() const {
        for (int rank = 1; rank < comm_.size(); ++rank)
            if (!progress_[static_cast<std::size_t>(rank)].done) return false;
        return true;
    }

    void wait(const WaitCmd& w) {
        Stopwatch t;
        for (;;) {
            if (all_done()) return;
            if (w.until == WaitCmd::Until::rays && double(total_rays()) >= w.amount) return;
            if (w.until == WaitCmd::Until::time) {
                if (t.seconds() >= w.amount) return;
                if (!comm_.probe(-1)) {
                    std::this_thread::sleep_for(std::chrono::milliseconds(1));
                    continue;
                }
            }
            int from = 0;
            auto [tag, bytes] = receive(&from);
            absorb(tag, bytes, from);
        }
    }

    struct Mosaic {
        Image image;
        std::vector<std::uint8_t> count;  // tiles that lit each pixel (overlaps)
    };

    Mosaic empty_mosaic() const {
        const PixelSize vs = virtual_screen_size(spec_);
        Mosaic m;
        m.image.resize(vs.width, vs.height);
        for (std::size_t i = 0; i < m.image.pixel_count(); ++i) {
            for (int k = 0; k < 3; ++k) m.image.rgba[4 * i + k] = kGap;
            m.image.rgba[4 * i + 3] = 255;
        }
        m.count.assign(m.image.pixel_count(), 0);
        return m;
    }

    void paste_image(Mosaic& m, const std::vector<std::byte>& bytes, int from) {
        const Stage left = trace_.switch_to(Stage::compose);
        MessageReader r(bytes, kResultVersion);
        r.get<std::uint64_t>();  // generation
        const auto rgba = r.get_bytes();
        const int tile = tile_of_rank(spec_, from);
        const PixelRect rect = tile_rect(spec_, tile);
        Image img;
        img.resize(rect.width, rect.height);
        if (rgba.size() != img.rgba.size())
            throw std::runtime_error("rank " + std::to_string(from) + ": tile image of the wrong size");
        std::memcpy(img.rgba.data(), rgba.data(), rgba.size());
        paste(m.image, img, rect, m.count);
        if (!o_.tiles_out.empty())
            write_image(std::filesystem::path(o_.tiles_out) / ("tile_" + std::to_string(tile) + ".png"), img);
        trace_.switch_to(left);
    }

    // Asks every tile for the image it shows now and pastes the answers into a mosaic.
    Image gather_images(Tag request) {
        for (int rank = 1; rank < comm_.size(); ++rank) comm_.send(rank, request, {});
        Mosaic mosaic = empty_mosaic();
        for (int got = 0; got < comm_.size() - 1;) {
            int from = 0;
            auto [tag, bytes] = receive(&from);
            if (tag != Tag::image) {
                absorb(tag, bytes, from);
                continue;
            }
            paste_image(mosaic, bytes, from);
            ++got;
        }
        return mosaic.image;
    }

    const WallOptions& o_;
    Comm& comm_;
    const WallSpec& spec_;
    Box3 bounds_;
    double iso_, lo_, hi_;
    float aspect_ = 1;
    Camera camera_;
    std::uint64_t generation_ = 0;
    std::vector<Progress> progress_;
    Stopwatch frame_start_;
    TraceRecorder trace_;
};

int run_master(const WallOptions& o, Comm& comm, const WallSpec& spec, const OpenedVolume& ov,
               SurfaceExtractor& ex, double iso, const std::vector<ScriptLine>& script) {
    WallMaster master(o, comm, spec, ov.volume.bounds(), iso, ex.value_min(), ex.value_max());
    master.print_map();
    master.send_views();
    const std::string where = o.script.empty() ? std::string("--script") : o.script;
    try {
        if (o.script == "-") {
            // The console: commands typed on the master's terminal; a typo is reported, not fatal.
            std::printf("console: orbit, look-at, zoom, iso, wait, snapshot, quit\n> ");
            std::fflush(stdout);
            int line = 0;
            for (std::string text; std::getline(std::cin, text);) {
                ++line;
                if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
                try {
                    if (!master.execute(parse_command(text, "console:" + std::to_string(line)), "console"))
                        break;
                } catch (const InputError& e) {
                    std::printf("isowall: %s\n", e.what());
                }
                std::printf("> ");
                std::fflush(stdout);
            }
        } else {
            for (const ScriptLine& l : script)
                if (!master.execute(l.command, where + ":" + std::to_string(l.line))) break;
        }
    } catch (const InputError& e) {
        std::fprintf(stderr, "isowall: error: %s\n", e.what());
        comm.abort(1);
    }
    if (o.script.empty()) master.execute(WaitCmd{WaitCmd::Until::done, 0}, where);
    return master.finish();
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
    std::vector<ScriptLine> script;
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
            to_engine_options(o.engine);  // a bad engine option stops the job before any frame
            // The whole script is checked before any frame starts: a bad line stops the job here.
            if (!o.script.empty() && o.script != "-") {
                std::ifstream in(o.script);
                if (!in) throw InputError(o.script, "--script", "cannot open the file");
                std::stringstream text;
                text << in.rdbuf();
                script = parse_script(text.str(), o.script);
            }
        } catch (const std::exception& e) {
            std::fprintf(stderr, "isowall: error: %s\n", e.what());
            comm.abort(1);  // the tile ranks wait at the barrier below
        }
    }
    comm.barrier();
    if (comm.is_master()) return run_master(o, comm, spec, *ov, *ex, iso, script);
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
