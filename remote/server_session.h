#pragma once
// The extraction side of one client of `isowall serve` (the dissertation's chapter 4), apart from
// sockets and threads: a request goes in, messages come out through a callback. The server
// (view_server.h) runs one session per connection on a thread of its own.
//
// A request is cast level by level: with progressive LOD (section 4.1.3) first at meta-cells of
// 4 and then 2 cells per side, each with about lod_ray_share of the view's rays, then at full
// resolution with a ray for every pixel the volume covers. Every group goes out as it is made.
//
// Cached primitives (section 4.1.4). The session decides what the client caches, as only it
// knows which requests its worker skipped (it takes the newest; a client that judged by the
// requests it sent could drop groups the session goes on to name). A cached request that cannot
// keep the cache (another isovalue, or the previous request did not cache) begins a generation
// numbered by its request id; each group sent while it lasts carries it (GroupMsg::cache_gen) and
// takes the next slot, the client's index of the group in its cache. The session keeps, per
// level, what it sent: each group's key, slot and the cells it took. A request that keeps the
// generation then
//   1. begins each level's frame with those cells taken again, under their groups' ids,
//   2. casts one ray towards each cached group's seed and names the slots of the groups those
//      rays meet first, every level in one VisibleMsg (the client draws coarse levels first),
//   3. casts as usual: a ray that meets a cell of a cached group not named yet names it (the
//      engine's GroupSink::seen, a VisibleMsg of one slot), a ray that meets a new part of the
//      surface makes a new group.
// So every group is sent once per generation, and at full resolution every pixel's ray names or
// makes the group it sees: the final image is the one without a cache. New coarse groups of a
// kept generation are sent with draw_from_next_frame (the client cannot draw them over the finer
// groups it already shows). A group cut short by an interrupt is not sent and its cells are not
// kept, so a later request makes it again. Groups of a request that does not cache carry
// generation 0. A cached request with id 0 is served uncached (0 names no generation).
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/util.h"
#include "engine/progressive_engine.h"
#include "extract/surface_extractor.h"
#include "remote/encoding_choice.h"
#include "remote/group_codec.h"
#include "remote/view_protocol.h"

namespace isowall::remote {

struct SessionOptions {
    EngineOptions engine;  // ray order, intersection, propagation; levels are set per level
    GroupEncoding encoding = GroupEncoding::compact_zstd;
    // The server chooses cells or compact+zstd per group (remote/encoding_choice.h); `encoding`
    // is then ignored.
    bool adaptive = false;
    int lod_levels = 2;  // coarse levels of progressive LOD before the full resolution
    // Rays of each coarse level, as a share of the view's pixels (the text: 0.1% - 1%). Whole
    // levels of the ray order are cast, so a level may take up to about 4x this.
    double lod_ray_share = 0.0025;
    // The server paces its sends to this (serve --rate-mbps); 0: unpaced. The adaptive chooser
    // takes it as the link's rate until it sees one.
    double link_cap_bytes_per_s = 0;
    // The client takes ExactMsg (its hello's takes_exact): a full-resolution cells group it does
    // not cache then goes with its gradients' voxels to a step, and their exact values follow
    // once the request's last group is out (remote/cell_codec.h). On the shared 16-bit volumes
    // the image before them is 99.6-99.8% correct, for 10-13% fewer bytes.
    bool exact_after = false;
};

// Sends one message; returns its bytes on the wire. Throws when the connection is gone.
using SendMessage = std::function<std::size_t(const RemoteMessage&)>;
// How far the link has taken what was sent (MessageChannel::link_progress); nullopt where the
// connection cannot tell.
using ReadLink = std::function<std::optional<LinkProgress>()>;

struct RequestFigures {
    bool completed = false;    // false: stopped by a newer request or a closed connection
    std::uint64_t rays = 0;    // every level's rays, the seed rays of step 2 included
    std::uint64_t groups = 0;  // groups sent
    std::uint64_t named = 0;   // cached groups named visible
    std::uint64_t triangles = 0;
    std::uint64_t bytes = 0;  // of every message sent for the request
    // The coarse picture's forecast C where the server chose the levels of detail
    // (LodSchedule::chosen; remote/lod_choice.h), else -1; coarse passes went out where it paid.
    double coarse_forecast = -1;
    std::size_t forecast_rays = 0;  // the forecast's rays at full resolution
    double forecast_s = 0;          // and its seconds
    int coarse_levels = 0;          // the coarse levels cast
};

// "; coarse picture forecast C = 0.925 (1329 rays, 4.1 ms): 2 coarse levels" where the server
// chose the levels of detail, else empty: for the server's line per request.
std::string lod_note(const RequestFigures& f);

class ServerSession {
  public:
    // `prototype` (the dataset's extractor) must outlive the session; the session's extractors
    // share its octree (SurfaceExtractor::share).
    ServerSession(const SurfaceExtractor& prototype, SessionOptions options, SendMessage send);
    ~ServerSession();
    ServerSession(const ServerSession&) = delete;
    ServerSession& operator=(const ServerSession&) = delete;

    // Casts the request's view and sends its groups, then an EndOfFrameMsg (not when stopped).
    // `stop` is read between rays (a newer request, a closed connection).
    RequestFigures run(const RequestMsg& request, const std::atomic<bool>& stop);
    // The next cached request begins a new generation (a shared session's follower joined).
    void restart_cache() { cache_valid_ = false; }
    // The client's decoding report (adaptive sessions); any thread: the chooser takes it before
    // its next group.
    void client_decoded(const DecodeRateMsg& report);
    // How the chooser may see what the link takes (adaptive sessions): read as each group is
    // ready to go (EncodingChooser::ready_to_send).
    void set_link_reader(ReadLink read) { read_link_ = std::move(read); }

  private:
    struct LodLevel;
    class Sink;
    LodLevel& lod_level(int l);
    void take_reports();
    // Reports held while the worker sends no group (a client may report faster than a stalled
    // worker takes them); past this they are dropped, as the chooser weighs the recent most.
    static constexpr std::size_t kMaxPendingReports = 64;
    void begin_cached(LodLevel& lv, const RequestMsg& r, bool keep);
    void name_by_seed_rays(const RequestMsg& r, int top, RequestFigures& f);
    // The coarse levels to cast before the full resolution, of the `most` the request allows:
    // all, or with LodSchedule::chosen those the forecast says bring C = 90% sooner (all or none).
    // A request that keeps the cache generation keeps the levels of the one before it: the
    // generation's coarse groups came with them, and a turned view at a cached isovalue reaches
    // C = 90% in a few milliseconds, which a forecast each time would double.
    int coarse_levels(const RequestMsg& r, int most, bool keep, RequestFigures& f);
    bool cast_level(int l, const RequestMsg& r, bool drawn, const std::atomic<bool>& stop,
                    RequestFigures& f);

    const SurfaceExtractor& prototype_;
    SessionOptions options_;
    SendMessage send_;
    ReadLink read_link_;
    Stopwatch since_start_;    // the clock of the link's progress
    EncodingChooser chooser_;  // options_.adaptive: which encoding each group goes in
    std::mutex reports_mutex_;
    std::vector<DecodeRateMsg> reports_;  // the client's, not yet taken by the chooser
    Stopwatch since_sent_;                // since the last group's send: the engine making the next
    std::vector<std::unique_ptr<LodLevel>> levels_;  // index = level of detail (0 = full)
    std::vector<ExactMsg> exact_due_;  // the request's exact values, sent after its last group
    bool cache_valid_ = false;
    double cache_iso_ = 0;
    std::uint64_t cache_gen_ = 0;  // the generation groups are sent in; 0 while not caching
    std::uint32_t next_slot_ = 0;  // the slot of the generation's next group
    float grid_step_ = 0;  // compact encodings: one position grid for every group (no cracks)
    int last_top_ = 0;     // the coarse levels the last request cast
};

}  // namespace isowall::remote
