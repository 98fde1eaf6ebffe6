#include "engine/group_sink.h"

#include <chrono>

namespace isowall {

void RendererSink::begin(const FrameView& view) {
    view_m_ = view.camera.view();
    proj_m_ = view.frustum.matrix();
    renderer_.resize(view.width, view.height);
    renderer_.clear();
}

void RendererSink::add(const Group& group) {
    renderer_.draw(group.mesh, view_m_, proj_m_);
}

double RendererSink::present() {
    const auto t0 = std::chrono::steady_clock::now();
    renderer_.finish();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

bool RendererSink::present_async() {
    renderer_.flush();
    return true;
}

bool RendererSink::presented(bool wait) {
    return renderer_.finished(wait);
}

bool RendererSink::coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) {
    renderer_.read_coverage(covered, rect);
    return true;
}

void RendererSink::read_back(Image& out) {
    renderer_.finish();
    renderer_.read_back(out);
}

void RendererSink::read_back(Image& out, const PixelRect& rect) {
    renderer_.finish();
    renderer_.read_back(out, rect);
}

void TeeSink::begin(const FrameView& view) {
    for (GroupSink* s : sinks_) s->begin(view);
}

void TeeSink::add(const Group& group) {
    for (GroupSink* s : sinks_) s->add(group);
}

double TeeSink::present() {
    double seconds = 0;
    for (GroupSink* s : sinks_) seconds += s->present();
    return seconds;
}

bool TeeSink::present_async() {
    for (GroupSink* s : sinks_)
        if (!s->present_async()) s->present();
    return true;
}

bool TeeSink::presented(bool wait) {
    bool all = true;
    for (GroupSink* s : sinks_) all = s->presented(wait) && all;
    return all;
}

bool TeeSink::coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) {
    for (GroupSink* s : sinks_)
        if (s->coverage(covered, rect)) return true;
    return false;
}

bool TeeSink::tells_coverage() const {
    for (const GroupSink* s : sinks_)
        if (s->tells_coverage()) return true;
    return false;
}

}  // namespace isowall
