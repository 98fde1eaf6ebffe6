#pragma once
// Constructors of the concrete back ends, for make_renderer() only. Declared here rather than in
// renderer.h so that their classes, and the GL headers they need, stay in their own .cpp files.
#include <memory>

#include "render/renderer.h"

namespace isowall {

std::unique_ptr<Renderer> make_osmesa_renderer();
std::unique_ptr<Renderer> make_egl_renderer();

}  // namespace isowall
