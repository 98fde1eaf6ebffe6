#include "remote/client_frames.h"

#include <span>
#include <type_traits>

#include "common/core/wire.h"
#include "remote/group_codec.h"

namespace isowall::remote {
namespace {

// Samples are taken as the frame grows by this factor in bytes, and at least this often.
constexpr double kSampleBytesFactor = 1.01;
constexpr double kSampleIntervalS = 0.01;

std::shared_ptr<const Mesh> decode_mesh(const GroupMsg& m) {
    std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(m.encoded.data()),
                                        m.encoded.size());
    Group g = decode_group(bytes);
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
    result_ = ClientFrameResult{};
    if (!request.cached_groups || !cache_valid_ || cache_iso_ != request.view.iso) cache_.clear();
    cache_valid_ = request.cached_groups;
    cache_iso_ = request.view.iso;
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

bool ClientFrames::handle(const ViewMessage& m, std::size_t wire_bytes, double now_s) {
    if (const auto* e = std::get_if<ErrorMsg>(&m)) throw RemoteError(e->code, e->text);
    if (const auto* g = std::get_if<GroupMsg>(&m)) {
        const bool current = active_ && g->request_id == request_.request_id;
        if (!current && !(cache_valid_ && g->key.iso == cache_iso_)) return false;
        auto mesh = decode_mesh(*g);
        if (cache_valid_ && g->key.iso == cache_iso_) cache_[g->key] = {mesh, g->key.level};
        if (!current) return false;
        now_.bytes += wire_bytes;
        ++now_.groups;
        if (!g->draw_from_next_frame) draw(mesh, g->key.level);
        sample(now_s, false);
        return false;
    }
    if (const auto* v = std::get_if<VisibleMsg>(&m)) {
        if (!active_ || v->request_id != request_.request_id) return false;
        now_.bytes += wire_bytes;
        for (const GroupKey& k : v->keys) {
            const auto it = cache_.find(k);
            if (it == cache_.end())
                throw WireError(
                    "visible message: keys: the server named a group the client "
                    "does not hold");
            ++now_.named;
            draw(it->second.mesh, it->second.level);
        }
        sample(now_s, false);
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
    if (drew_coarse_) {
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
