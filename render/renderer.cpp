#include "render/renderer.h"

#include <algorithm>
#include <string>

namespace isowall {

RendererError::RendererError(std::string_view source, std::string_view message)
    : std::runtime_error(std::string(source) + ": " + std::string(message)) {}

void Renderer::read_coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) {
    Image frame;
    read_back(frame, rect);
    covered.assign(static_cast<std::size_t>(std::max(0, rect.width)) *
                       static_cast<std::size_t>(std::max(0, rect.height)),
                   0);
    if (frame.depth.size() != covered.size()) return;  // a renderer that draws nothing
    for (std::size_t i = 0; i < covered.size(); ++i) covered[i] = frame.depth[i] < 1.0f;
}

void warm_up(Renderer& renderer) {
    Mesh tiny;
    tiny.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    tiny.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    tiny.indices = {0, 1, 2};
    renderer.resize(16, 16);
    renderer.clear();
    renderer.draw(tiny, glm::mat4(1.0f), glm::mat4(1.0f));
    renderer.finish();
    // Each way a frame is read back, and a draw over a cleared depth: first calls of these set up
    // Mesa's paths too.
    Image image;
    renderer.read_back(image);
    renderer.read_back(image, PixelRect{0, 0, 8, 8});
    std::vector<std::uint8_t> covered;
    renderer.read_coverage(covered, PixelRect{0, 0, 8, 8});
    renderer.clear_depth();
    renderer.draw(tiny, glm::mat4(1.0f), glm::mat4(1.0f));
    renderer.finish();
}

Image draw_alone(Renderer& renderer, const Mesh& mesh, const FrameView& view) {
    Image image;
    renderer.resize(view.width, view.height);
    renderer.clear();
    renderer.draw(mesh, view.camera.view(), view.frustum.matrix());
    renderer.read_back(image);
    return image;
}

}  // namespace isowall
