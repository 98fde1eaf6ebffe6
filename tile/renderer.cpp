#include "tile/renderer.h"

#include <algorithm>
#include <string>

#include "tile/backends.h"

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

std::unique_ptr<Renderer> make_renderer(std::string_view backend) {
    if (backend == "osmesa") return make_osmesa_renderer();
    if (backend == "egl") return make_egl_renderer();
    throw RendererError("make_renderer", "unknown back end \"" + std::string(backend) +
                                             "\"; expected \"osmesa\" or \"egl\"");
}

}  // namespace isowall
