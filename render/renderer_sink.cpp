#include "render/renderer_sink.h"

#include <chrono>

#include "core/sample_cull.h"

namespace isowall {

void RendererSink::begin(const FrameView& view) {
    view_m_ = view.camera.view();
    proj_m_ = view.frustum.matrix();
    width_ = view.width;
    height_ = view.height;
    given_ = drawn_ = 0;
    renderer_.resize(view.width, view.height);
    renderer_.clear();
}

void RendererSink::add(const Group& group) {
    given_ += group.mesh.triangle_count();
    if (every_triangle_) {
        drawn_ += group.mesh.triangle_count();
        renderer_.draw(group.mesh, view_m_, proj_m_);
        return;
    }
    drawn_ +=
        keep_sampled_triangles(group.mesh, proj_m_ * view_m_, width_, height_, sampled_, scratch_);
    renderer_.draw(sampled_, view_m_, proj_m_);
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

void RendererSink::coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) {
    renderer_.read_coverage(covered, rect);
}

void RendererSink::read_back(Image& out) {
    renderer_.finish();
    renderer_.read_back(out);
}

void RendererSink::read_back(Image& out, const PixelRect& rect) {
    renderer_.finish();
    renderer_.read_back(out, rect);
}

}  // namespace isowall
