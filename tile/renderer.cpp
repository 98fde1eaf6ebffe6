#include "tile/renderer.h"

#include <string>

#include "tile/backends.h"

namespace isowall {

RendererError::RendererError(std::string_view source, std::string_view message)
    : std::runtime_error(std::string(source) + ": " + std::string(message)) {}

std::unique_ptr<Renderer> make_renderer(std::string_view backend) {
    if (backend == "osmesa") return make_osmesa_renderer();
    if (backend == "egl") return make_egl_renderer();
    throw RendererError("make_renderer", "unknown back end \"" + std::string(backend) +
                                             "\"; expected \"osmesa\" or \"egl\"");
}

}  // namespace isowall
