#include "remote/client_frames.h"

#include <algorithm>
#include <span>
#include <string>
#include <type_traits>

#include "core/util.h"
#include "remote/group_codec.h"
#include "wire/wire.h"

namespace isowall::remote {
namespace {

// Samples are taken as the frame grows by this factor in bytes, and at least this often.
constexpr double kSampleBytesFactor = 1.01;
constexpr double kSampleIntervalS = 0.01;

std::span<const std::uint8_t> as_bytes(const std::vector<std::byte>& b) {
    return {reinterpret_cast<const std::uint8_t*>(b.data()), b.size()};
}

// The group's mesh; with `x`, exact values to decode it with, or where to say it was stepped.
std::shared_ptr<const Mesh> decode_mesh(const GroupMsg& m, const CellExact& x) {
    Group g = decode_group(as_bytes(m.encoded), x);
    if (!(g.key() == m.key))
        throw WireError("group message: key: the encoded group is another group");
    return std::make_shared<const Mesh>(std::move(g.mesh));
}

}  // namespace

void ClientFrames::begin(const RequestMsg& request, double now_s) {
    request_ = request;
    active_ = true;
    start_s_ = now_s;
    last_sample_s_ = -1;
    last_sample_bytes_ = 0;
    now_ = ClientSample{};
    draw_level_ = 1 << 30;
    drew_coarse_ = false;
    redraw_op_ = SIZE_MAX;
    ops_.clear();
    finals_.clear();
    stepped_.clear();
    replaced_ = false;
    result_ = ClientFrameResult{};
    renderer_.resize(request.view.width, request.view.height);
    renderer_.clear();
    sample(now_s, true);
}

void ClientFrames::draw(const std::shared_ptr<const Mesh>& mesh, int level) {
    if (level > draw_level_) return;  // coarser than what shows: cached, drawn from the next frame
    if (level < draw_level_ && !ops_.empty()) {
        renderer_.clear_depth();
        ops_.push_back({nullptr});
    }
    draw_level_ = level;
    now_.level = level;
    drew_coarse_ = drew_coarse_ || level > 0;
    renderer_.draw(*mesh, request_.view.camera.view(), request_.view.frustum.matrix());
    ops_.push_back({mesh});
    if (level == 0) finals_.push_back(mesh);
    now_.triangles += mesh->triangle_count();
}

void ClientFrames::sample(double now_s, bool force) {
    now_.time_s = now_s - start_s_;
    now_.ops = ops_.size();
    if (!force && double(now_.bytes) < double(last_sample_bytes_) * kSampleBytesFactor &&
        now_.time_s - last_sample_s_ < kSampleIntervalS)
        return;
    result_.timeline.push_back(now_);
    last_sample_s_ = now_.time_s;
    last_sample_bytes_ = now_.bytes;
}

void ClientFrames::handle_group(const GroupMsg& g, std::size_t wire_bytes, double now_s) {
    const bool current = active_ && g.request_id == request_.request_id;
    if (!current && g.cache_gen == 0) return;
    const Stopwatch decoding;
    bool stepped = false;
    auto mesh = decode_mesh(g, {nullptr, &stepped});
    if (stepped && g.cache_gen != 0)
        throw WireError("group message: a group to cache came with its values to a step");
    // decode_mesh checked the encoding byte.
    DecodeRateMsg::Entry& d = decoded_[static_cast<std::size_t>(g.encoded[1])];
    d.triangles += mesh->triangle_count();
    d.seconds += decoding.seconds();
    if (g.cache_gen != 0) {
        if (g.cache_gen != cache_gen_) {
            cache_.clear();
            cache_gen_ = g.cache_gen;
        }
        cache_.push_back({mesh, g.key.level});
    }
    if (!current) return;
    // The coarse passes' picture as it stands before the first full-resolution group covers it:
    // a sample of its own, whatever the sampling's pace.
    if (!g.draw_from_next_frame && g.key.level == 0 && drew_coarse_ && draw_level_ > 0)
        sample(now_s, true);
    now_.bytes += wire_bytes;
    ++now_.groups;
    if (g.encoded.size() > 1 &&
        g.encoded[1] == std::byte{static_cast<std::uint8_t>(GroupEncoding::cells)})
        ++now_.cells;
    const std::size_t finals_before = finals_.size();
    if (!g.draw_from_next_frame) draw(mesh, g.key.level);
    if (stepped)
        stepped_.push_back(
            {g.key, g.encoded, finals_.size() > finals_before ? finals_before : SIZE_MAX});
    sample(now_s, false);
}

void ClientFrames::handle_exact(const ExactMsg& x, std::size_t wire_bytes, double now_s) {
    if (!active_ || x.request_id != request_.request_id) return;
    const auto it = std::find_if(stepped_.begin(), stepped_.end(),
                                 [&](const Stepped& s) { return s.key == x.key; });
    if (it == stepped_.end())
        throw WireError("exact message: key: no group of the request awaits exact values");
    const Stopwatch decoding;
    const std::span<const std::uint8_t> bits = as_bytes(x.bits);
    GroupMsg g;
    g.key = it->key;
    g.encoded = std::move(it->encoded);
    auto mesh = decode_mesh(g, {&bits, nullptr});
    // The second decoding of a cells group is the client's work too (its triangles were counted).
    decoded_[static_cast<std::size_t>(GroupEncoding::cells)].seconds += decoding.seconds();
    now_.bytes += wire_bytes;
    ++now_.exact;
    if (it->final_index != SIZE_MAX) {
        finals_[it->final_index] = mesh;
        // Over the stepped surface, which lies within a hair of it: the frame's end draws the
        // full-resolution groups again alone.
        renderer_.draw(*mesh, request_.view.camera.view(), request_.view.frustum.matrix());
        ops_.push_back({mesh});
        replaced_ = true;
    }
    stepped_.erase(it);
    sample(now_s, false);
}

void ClientFrames::handle_visible(const VisibleMsg& v, std::size_t wire_bytes, double now_s) {
    if (!active_ || v.request_id != request_.request_id) return;
    now_.bytes += wire_bytes;
    std::vector<const Cached*> named;
    named.reserve(v.slots.size());
    for (const std::uint32_t slot : v.slots) {
        if (slot >= cache_.size())
            throw WireError(
                "visible message: slots: the server named a group the client does not "
                "hold (slot " +
                std::to_string(slot) + " of " + std::to_string(cache_.size()) + ")");
        named.push_back(&cache_[slot]);
    }
    // Coarse first: draw() skips a group coarser than what the frame already shows.
    std::stable_sort(named.begin(), named.end(),
                     [](const Cached* a, const Cached* b) { return a->level > b->level; });
    for (const Cached* c : named) {
        ++now_.named;
        draw(c->mesh, c->level);
    }
    sample(now_s, false);
}

std::optional<DecodeRateMsg> ClientFrames::decode_report(double now_s) {
    if (now_s - last_report_s_ < kReportEveryS) return std::nullopt;
    DecodeRateMsg m;
    for (std::size_t e = 0; e < decoded_.size(); ++e) {
        if (decoded_[e].triangles == 0) continue;
        m.entries.push_back(
            {static_cast<std::uint8_t>(e), decoded_[e].triangles, decoded_[e].seconds});
        decoded_[e] = {};
    }
    if (m.entries.empty()) return std::nullopt;
    last_report_s_ = now_s;
    return m;
}

bool ClientFrames::handle(const RemoteMessage& m, std::size_t wire_bytes, double now_s) {
    if (const auto* e = std::get_if<ErrorMsg>(&m)) throw RemoteError(e->code, e->text);
    if (const auto* g = std::get_if<GroupMsg>(&m)) {
        handle_group(*g, wire_bytes, now_s);
        return false;
    }
    if (const auto* v = std::get_if<VisibleMsg>(&m)) {
        handle_visible(*v, wire_bytes, now_s);
        return false;
    }
    if (const auto* x = std::get_if<ExactMsg>(&m)) {
        handle_exact(*x, wire_bytes, now_s);
        return false;
    }
    if (const auto* e = std::get_if<EndOfFrameMsg>(&m)) {
        if (!active_ || e->request_id != request_.request_id) return false;
        now_.bytes += wire_bytes;
        finish_frame(*e, now_s);
        return true;
    }
    return false;  // ready, hello, request, bye: not part of a frame
}

void ClientFrames::finish_frame(const EndOfFrameMsg& end, double now_s) {
    if (!stepped_.empty())
        throw WireError("end of frame message: " + std::to_string(stepped_.size()) +
                        " groups of the request never got their exact values");
    if (drew_coarse_ || replaced_) {
        // The full-resolution groups alone: no coarse surface outside the fine one stays.
        renderer_.clear();
        redraw_op_ = ops_.size();
        ops_.push_back({nullptr});  // the replay clears everything here
        for (const auto& mesh : finals_) {
            renderer_.draw(*mesh, request_.view.camera.view(), request_.view.frustum.matrix());
            ops_.push_back({mesh});
        }
    }
    sample(now_s, true);
    active_ = false;
    result_.completed = true;
    result_.end = end;
    renderer_.read_back(result_.final_image);
}

void ClientFrames::measure() {
    if (!result_.completed) return;
    renderer_.clear();
    std::size_t done = 0;
    Image image;
    // Pixels drawn before a depth clear: their colour stays on screen, so they count as drawn.
    std::vector<std::uint8_t> drawn;
    for (ClientSample& s : result_.timeline) {
        for (; done < s.ops; ++done) {
            const Op& op = ops_[done];
            if (done == redraw_op_) {
                renderer_.clear();
                drawn.clear();
            } else if (!op.mesh) {
                renderer_.read_back(image);
                mark_drawn(image, drawn);
                renderer_.clear_depth();
            } else {
                renderer_.draw(*op.mesh, request_.view.camera.view(),
                               request_.view.frustum.matrix());
            }
        }
        renderer_.read_back(image);
        s.correctness = measure_correctness(image, result_.final_image, 1, drawn);
    }
}

}  // namespace isowall::remote
