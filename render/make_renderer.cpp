#include <string>

#include "render/backends.h"

namespace isowall {

std::unique_ptr<Renderer> make_renderer(std::string_view backend) {
    if (backend == "osmesa") return make_osmesa_renderer();
    if (backend == "egl") return make_egl_renderer();
    throw RendererError("make_renderer", "unknown back end \"" + std::string(backend) +
                                             "\"; expected \"osmesa\" or \"egl\"");
}

}  // namespace isowall
