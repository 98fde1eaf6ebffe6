#include "bench/peer/peer_trace.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include <glm/gtc/matrix_inverse.hpp>

#include "core/ray.h"
#include "core/util.h"

namespace isowall::peer {
namespace {

// 8x8 pixel tiles: one packet of 8 rays per tile row. Tile counts are ceiling divisions and the
// last tile's packets mask off the pixels past the edge, so edge tiles need no special case.
constexpr int kTile = 8;

// Embree reports every error through one callback (its minimal tutorial); we keep the last
// message and turn it into an exception after the call that raised it.
struct Device {
    RTCDevice device = nullptr;
    std::mutex mutex;
    std::string last_error;

    explicit Device(int threads) {
        const std::string config = "threads=" + std::to_string(threads) + ",set_affinity=0";
        device = rtcNewDevice(config.c_str());
        if (!device) throw std::runtime_error("embree: rtcNewDevice: " + config + " refused");
        rtcSetDeviceErrorFunction(device, &Device::on_error, this);
    }
    ~Device() { rtcReleaseDevice(device); }
    Device(const Device&) = delete;
    Device& operator=(const Device&) = delete;

    static void on_error(void* self, RTCError code, const char* message) {
        auto* d = static_cast<Device*>(self);
        std::lock_guard lock(d->mutex);
        d->last_error = std::to_string(int(code)) + " (" + (message ? message : "") + ")";
    }
    void check(const char* call) {
        if (rtcGetDeviceError(device) == RTC_ERROR_NONE) return;
        std::lock_guard lock(mutex);
        throw std::runtime_error(std::string("embree: ") + call + ": error " + last_error);
    }
};

struct Scene {
    RTCScene scene;
    explicit Scene(Device& d) : scene(rtcNewScene(d.device)) { d.check("rtcNewScene"); }
    ~Scene() { rtcReleaseScene(scene); }
    Scene(const Scene&) = delete;
    Scene& operator=(const Scene&) = delete;
};

// One triangle geometry holding a copy of the mesh (as OSPRay copies into its own buffers).
void attach_mesh(Device& d, RTCScene scene, const PeerMesh& mesh) {
    if (mesh.triangle_count() == 0) return;  // an empty scene: every ray misses
    RTCGeometry geom = rtcNewGeometry(d.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    d.check("rtcNewGeometry");
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                          RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                          mesh.vertex_count()));
    auto* t = static_cast<std::uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(std::uint32_t), mesh.triangle_count()));
    d.check("rtcSetNewGeometryBuffer");
    std::memcpy(v, mesh.xyz.data(), mesh.xyz.size() * sizeof(float));
    std::memcpy(t, mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t));
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    d.check("rtcCommitGeometry");
}

// The 8 rays of tile row (x0, y): pixels past the right edge are masked off in `valid`.
void fill_packet(const glm::mat4& view_inverse, const TraceView& v, int x0, int y, RTCRayHit8& rh,
                 int* valid) {
    for (int i = 0; i < 8; ++i) {
        const int x = std::min(x0 + i, v.width - 1);
        valid[i] = x0 + i < v.width ? -1 : 0;
        const Ray r = pixel_ray(view_inverse, v.frustum, v.width, v.height, {x, y});
        rh.ray.org_x[i] = r.o.x;
        rh.ray.org_y[i] = r.o.y;
        rh.ray.org_z[i] = r.o.z;
        rh.ray.dir_x[i] = r.d.x;
        rh.ray.dir_y[i] = r.d.y;
        rh.ray.dir_z[i] = r.d.z;
        rh.ray.tnear[i] = 0.0f;
        rh.ray.tfar[i] = std::numeric_limits<float>::infinity();
        rh.ray.time[i] = 0.0f;
        rh.ray.mask[i] = ~0u;
        rh.ray.id[i] = unsigned(i);
        rh.ray.flags[i] = 0;
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    }
}

// Threads take tiles from a shared counter; each writes only its tiles' pixels of `hits` and
// counts its own hits (per-thread statistics, merged at the end), so nothing is locked.
std::size_t cast_tiles(RTCScene scene, const TraceView& v, int threads,
                       std::vector<std::uint8_t>& hits) {
    const int tiles_x = (v.width + kTile - 1) / kTile, tiles_y = (v.height + kTile - 1) / kTile;
    const glm::mat4 view_inverse = glm::inverse(v.camera.view());
    std::atomic<int> next{0};
    std::vector<std::size_t> counts(std::size_t(threads), 0);
    auto work = [&](int thread) {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        alignas(32) RTCRayHit8 rh;
        alignas(32) int valid[8];
        std::size_t mine = 0;
        for (int tile = next++; tile < tiles_x * tiles_y; tile = next++) {
            const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
            for (int y = y0; y < std::min(y0 + kTile, v.height); ++y) {
                fill_packet(view_inverse, v, x0, y, rh, valid);
                rtcIntersect8(valid, scene, &context, &rh);
                for (int i = 0; i < 8 && x0 + i < v.width; ++i) {
                    const bool hit = rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
                    hits[std::size_t(y) * std::size_t(v.width) + std::size_t(x0 + i)] = hit;
                    mine += hit;
                }
            }
        }
        counts[std::size_t(thread)] = mine;
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(work, t);
    work(0);
    for (auto& t : pool) t.join();
    std::size_t total = 0;
    for (std::size_t c : counts) total += c;
    return total;
}

}  // namespace

TraceView front_view(const Box3& bounds, int width, int height) {
    const float aspect = float(width) / float(height);
    TraceView v;
    v.camera = fit_depth_range(front_full_view(bounds, aspect), bounds);
    v.frustum = v.camera.frustum(aspect);
    v.width = width;
    v.height = height;
    return v;
}

TraceResult trace(const PeerMesh& mesh, const TraceView& view, int threads) {
    if (threads < 1 || view.width < 1 || view.height < 1)
        throw std::invalid_argument("peer trace: threads and screen size must be positive");
    Device device(threads);
    Scene scene(device);
    TraceResult r;
    Stopwatch sw;
    attach_mesh(device, scene.scene, mesh);
    rtcSetSceneBuildQuality(scene.scene, RTC_BUILD_QUALITY_MEDIUM);
    rtcCommitScene(scene.scene);
    device.check("rtcCommitScene");
    r.bvh_s = sw.seconds();
    r.hits.assign(std::size_t(view.width) * std::size_t(view.height), 0);
    sw.restart();
    r.hit_pixels = cast_tiles(scene.scene, view, threads, r.hits);
    r.rays_s = sw.seconds();
    device.check("rtcIntersect8");
    return r;
}

}  // namespace isowall::peer
