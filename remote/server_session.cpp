#include "remote/server_session.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

#include "core/ray.h"
#include "core/util.h"
#include "progressive/trace.h"
#include "remote/lod_choice.h"
#include "remote/view_framing.h"

namespace isowall::remote {
namespace {

// The pixel whose centre sees `p` (object space), if it is on the screen.
std::optional<glm::ivec2> pixel_of(const FrameView& v, glm::vec3 p) {
    return clip_to_pixel(v.frustum.matrix() * v.camera.view() * glm::vec4(p, 1.0f), v.width,
                         v.height);
}

}  // namespace

// One level of detail: its extractor (own visited cells, shared octree) and what was sent.
struct ServerSession::LodLevel {
    int lod = 0;
    std::unique_ptr<SurfaceExtractor> ex;
    struct Sent {
        GroupKey key;
        std::vector<glm::ivec3> cells;  // the first cell of each unit the group took
        std::uint32_t slot = 0;         // its index in the client's cache of the generation
    };
    std::vector<Sent> sent;   // index = the group's id in this level's frames
    std::vector<char> named;  // per sent group: named (or sent) in the current request
};

// Sends each group as it is made, and names cached groups that rays meet.
class ServerSession::Sink final : public GroupSink, public SeenGroups {
  public:
    Sink(ServerSession& s, LodLevel& lv, const RequestMsg& r, bool keep, RequestFigures& f)
        : s_(s), lv_(lv), r_(r), keep_(keep), f_(f) {
        s_.since_sent_.restart();  // the time before this pass's first group is its making
    }

    void add(const Group& g) override {
        GroupMsg m;
        m.request_id = r_.request_id;
        m.key = g.key();
        m.draw_from_next_frame = keep_ && lv_.lod > 0;
        m.cache_gen = s_.cache_gen_;  // 0 unless this request caches
        const bool adaptive = s_.options_.adaptive;
        const double making_s = s_.since_sent_.seconds();  // the engine made the group meanwhile
        // Encodes in `e` and tells the chooser what asking for `e` cost: cells fall back to
        // compact+zstd where that is smaller (a coarse pass), and the chooser learns it so.
        std::vector<std::uint8_t> exact;
        const auto encode = [&](GroupEncoding e, std::vector<std::uint8_t>* x) {
            // Thread CPU time: a wall clock charged an encoding for the scheduler's preemptions
            // (a page and the server on 2 cores), and one compact+zstd group that read 20 ms
            // made compact+zstd look dearer than cells for hundreds of groups.
            const double cpu0 = thread_cpu_seconds();
            std::vector<std::uint8_t> b =
                encode_group(g, e, s_.grid_step_, &s_.prototype_.volume(), x);
            if (adaptive)
                s_.chooser_.encoded(e, g.mesh.triangle_count(), b.size(),
                                    thread_cpu_seconds() - cpu0, making_s);
            return b;
        };
        GroupEncoding asked = s_.options_.encoding;
        // A group the chooser wants measured the other way too is encoded so after it is sent
        // (EncodingChooser::wants_measure): the link and the client work on it meanwhile.
        bool measure_other = false;
        if (adaptive) {
            s_.take_reports();
            if (s_.read_link_)
                s_.chooser_.ready_to_send(s_.read_link_(), s_.since_start_.seconds());
            asked = s_.chooser_.next(s_.since_start_.seconds());
            measure_other = s_.chooser_.wants_measure(other_encoding(asked));
        }
        // A group the client does not cache may go with its gradients' voxels to a step first:
        // when the server chooses, only where the link bounds cells.
        const bool stepped_first =
            s_.options_.exact_after && s_.cache_gen_ == 0 && (!adaptive || s_.chooser_.steps_pay());
        const std::vector<std::uint8_t> bytes = encode(asked, stepped_first ? &exact : nullptr);
        m.encoded.resize(bytes.size());
        std::transform(bytes.begin(), bytes.end(), m.encoded.begin(),
                       [](std::uint8_t b) { return std::byte{b}; });
        const Stopwatch sending;
        const long switches = voluntary_switches();
        const std::size_t sent = s_.send_(m);
        if (adaptive)
            s_.chooser_.sent(asked, sent, sending.seconds(), voluntary_switches() != switches);
        if (measure_other) encode(other_encoding(asked), nullptr);
        if (!exact.empty()) {
            ExactMsg x{r_.request_id, m.key, {}};
            x.bits.resize(exact.size());
            std::transform(exact.begin(), exact.end(), x.bits.begin(),
                           [](std::uint8_t b) { return std::byte{b}; });
            s_.exact_due_.push_back(std::move(x));
        }
        s_.since_sent_.restart();
        f_.bytes += sent;
        ++f_.groups;
        f_.triangles += g.mesh.triangle_count();
        if (s_.cache_gen_ == 0) return;
        // The engine numbers a frame's groups from first_group_id = sent.size(), one per add().
        if (g.id != lv_.sent.size())
            throw std::logic_error("server session: group ids out of step with the cache");
        lv_.sent.push_back({g.key(), g.cells, s_.next_slot_++});
        lv_.named.push_back(1);
    }

    // Cached groups are named only in a request that caches.
    FrameOutput output() {
        return FrameOutput(*this, nullptr, s_.cache_gen_ != 0 ? this : nullptr);
    }

    void seen(std::uint32_t id) override {
        if (id >= lv_.named.size() || lv_.named[id]) return;
        lv_.named[id] = 1;
        VisibleMsg m;
        m.request_id = r_.request_id;
        m.slots.push_back(lv_.sent[id].slot);
        f_.bytes += s_.send_(m);
        ++f_.named;
    }

  private:
    ServerSession& s_;
    LodLevel& lv_;
    const RequestMsg& r_;
    const bool keep_;
    RequestFigures& f_;
};

ServerSession::ServerSession(const SurfaceExtractor& prototype, SessionOptions options,
                             SendMessage send)
    : prototype_(prototype), options_(std::move(options)), send_(std::move(send)) {
    options_.lod_levels = std::clamp(options_.lod_levels, 0, kMaxMetaLevel);
    const Box3 b = prototype.volume().bounds();
    const glm::vec3 far = glm::max(glm::abs(b.min), glm::abs(b.max));
    grid_step_ = position_grid_step(2 * std::max({far.x, far.y, far.z}));
    if (options_.link_cap_bytes_per_s > 0) chooser_.set_link_cap(options_.link_cap_bytes_per_s);
}

ServerSession::~ServerSession() = default;

static_assert(kDecodeRateEncodings == static_cast<unsigned>(GroupEncoding::cells) + 1,
              "DecodeRateMsg names every group encoding");

void ServerSession::client_decoded(const DecodeRateMsg& report) {
    const std::lock_guard<std::mutex> lock(reports_mutex_);
    if (reports_.size() < kMaxPendingReports) reports_.push_back(report);
}

void ServerSession::take_reports() {
    std::vector<DecodeRateMsg> reports;
    {
        const std::lock_guard<std::mutex> lock(reports_mutex_);
        reports.swap(reports_);
    }
    for (const DecodeRateMsg& r : reports)
        for (const DecodeRateMsg::Entry& e : r.entries)
            chooser_.decoded(static_cast<GroupEncoding>(e.encoding), e.triangles, e.seconds);
}

ServerSession::LodLevel& ServerSession::lod_level(int l) {
    while (levels_.size() <= static_cast<std::size_t>(l)) {
        auto lv = std::make_unique<LodLevel>();
        lv->lod = static_cast<int>(levels_.size());
        lv->ex = prototype_.share();
        levels_.push_back(std::move(lv));
    }
    return *levels_[static_cast<std::size_t>(l)];
}

void ServerSession::begin_cached(LodLevel& lv, const RequestMsg& r, bool keep) {
    lv.ex->begin_frame(r.view.iso, uniform_levels(lv.lod));
    if (!keep) lv.sent.clear();
    for (std::size_t i = 0; i < lv.sent.size(); ++i)
        for (const glm::ivec3 c : lv.sent[i].cells)
            lv.ex->mark_taken(c, lv.sent[i].key.level, static_cast<std::uint32_t>(i));
    lv.named.assign(lv.sent.size(), 0);
}

// Step 2 of a cached isovalue: one ray towards each cached group's seed, coarse levels first,
// named in one message (the client orders its draws by level).
void ServerSession::name_by_seed_rays(const RequestMsg& r, int top, RequestFigures& f) {
    const FrameView& v = r.view;
    const glm::mat4 view_inv = glm::inverse(v.camera.view());
    const glm::vec3 spacing = prototype_.volume().spacing();
    VisibleMsg m;
    m.request_id = r.request_id;
    for (int l = top; l >= 0; --l) {
        LodLevel& lv = lod_level(l);
        for (const LodLevel::Sent& s : lv.sent) {
            const float half = 0.5f * float(1 << s.key.level);
            const auto px = pixel_of(v, (glm::vec3(s.key.seed) + half) * spacing);
            if (!px) continue;
            const Ray ray = pixel_ray(view_inv, v.frustum, v.width, v.height, *px);
            const RayHit hit = lv.ex->cast(ray, IntersectMode::exact);
            ++f.rays;
            if (!hit.found || !lv.ex->visited(hit.cell)) continue;
            const std::uint32_t id = lv.ex->group_of(hit.cell);
            if (id >= lv.named.size() || lv.named[id]) continue;
            lv.named[id] = 1;
            m.slots.push_back(lv.sent[id].slot);
        }
    }
    if (m.slots.empty()) return;
    std::sort(m.slots.begin(), m.slots.end());  // the wire wants them ascending
    f.named += m.slots.size();
    f.bytes += send_(m);
}

std::string lod_note(const RequestFigures& f) {
    if (f.coarse_forecast < 0) return {};
    char note[128];
    std::snprintf(note, sizeof(note),
                  "; coarse picture forecast C = %.3f (%zu rays, %.1f ms): %d coarse levels",
                  f.coarse_forecast, f.forecast_rays, 1e3 * f.forecast_s, f.coarse_levels);
    return note;
}

int ServerSession::coarse_levels(const RequestMsg& r, int most, bool keep, RequestFigures& f) {
    if (r.lod != LodSchedule::chosen || most == 0) return most;
    if (keep) return std::min(last_top_, most);
    std::vector<SurfaceExtractor*> levels;
    for (int l = 0; l <= most; ++l) levels.push_back(lod_level(l).ex.get());
    const Stopwatch took;
    const CoarseForecast forecast = forecast_coarse_correctness(levels, r.view, /*decide=*/true);
    f.forecast_s = took.seconds();
    f.forecast_rays = forecast.rays;
    f.rays += forecast.casts;
    f.coarse_forecast = forecast.c;
    return coarse_passes_pay(forecast) ? most : 0;
}

bool ServerSession::cast_level(int l, const RequestMsg& r, bool keep, const std::atomic<bool>& stop,
                               RequestFigures& f) {
    LodLevel& lv = lod_level(l);
    EngineOptions eo = options_.engine;
    eo.uniform_level = l;
    eo.adaptive = false;
    // The client keeps groups for later views (cached groups): they hold every triangle, not
    // only those that cover a pixel centre of this view.
    eo.sampled_triangles = false;
    eo.begin_extractor_frame = false;  // begin_cached began it, with the cached cells taken
    eo.first_group_id = static_cast<std::uint32_t>(lv.sent.size());
    eo.trace = nullptr;
    eo.sample_at_rays.clear();
    // A cached group is named to the client as soon as a ray meets it, not at the end of the
    // ray-order level, which one thread gives (EngineOptions::threads, SeenGroups).
    if (cache_gen_ != 0) eo.threads = 1;
    ProgressiveEngine engine(*lv.ex, eo);
    Sink sink(*this, lv, r, keep, f);
    EngineFrame frame(engine, r.view, stop);
    RegionCursor c = frame.cursor(r.view, r.view.screen());
    std::size_t limit = SIZE_MAX;
    if (l > 0) {
        const double pixels = double(r.view.width) * double(r.view.height);
        limit = std::max<std::size_t>(1, static_cast<std::size_t>(options_.lod_ray_share * pixels));
    }
    const bool ok = frame.cast(r.view, c, sink.output(), limit);
    f.rays += frame.finish(ok).rays_cast;
    return ok && !stop.load();
}

RequestFigures ServerSession::run(const RequestMsg& r, const std::atomic<bool>& stop) {
    RequestFigures f;
    // A generation past half the slots a VisibleMsg may name begins again, so its slots stay
    // nameable unless one request sends half a million groups.
    const bool keep = r.cached_groups && cache_valid_ && cache_iso_ == r.view.iso &&
                      next_slot_ < kMaxVisibleKeys / 2;
    cache_valid_ = r.cached_groups && r.request_id != 0;
    cache_iso_ = r.view.iso;
    if (!keep) {
        // A new generation, named by the request that began it: the client drops its cache when
        // a group of another generation arrives, whichever requests either side skipped.
        cache_gen_ = cache_valid_ ? r.request_id : 0;
        next_slot_ = 0;
        for (auto& lv : levels_) lv->sent.clear();
    }
    exact_due_.clear();
    // Every level the request may cast begins (the forecast casts on them), with its cached cells.
    const int most = r.lod == LodSchedule::off ? 0 : options_.lod_levels;
    for (int l = most; l >= 0; --l) begin_cached(lod_level(l), r, keep);
    const int top = coarse_levels(r, most, keep, f);
    f.coarse_levels = last_top_ = top;
    if (keep) name_by_seed_rays(r, top, f);
    for (int l = top; l >= 0; --l)
        if (stop.load() || !cast_level(l, r, keep, stop, f)) return f;
    // The exact values, once every group is out: the picture is whole first, then exact.
    for (const ExactMsg& x : exact_due_) {
        if (stop.load()) return f;
        f.bytes += send_(x);
    }
    exact_due_.clear();
    EndOfFrameMsg end;
    end.request_id = r.request_id;
    end.rays = f.rays;
    end.groups = f.groups;
    end.triangles = f.triangles;
    end.bytes = f.bytes + kHeaderBytes + encode_payload(end).size();
    f.bytes += send_(end);
    f.completed = true;
    return f;
}

}  // namespace isowall::remote
