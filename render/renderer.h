#pragma once
// The tile renderer: draws meshes into an off-screen frame and reads it back as an Image. Back
// ends (OSMesa, EGL) hide behind this interface, so no caller ever sees a GL or EGL header.
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/camera.h"
#include "core/image.h"
#include "core/mesh.h"
#include "core/view.h"

namespace isowall {

// Every renderer failure: the message starts with the back end (or "make_renderer") and names the
// failing call, e.g. "egl: eglInitialize failed (EGL_NOT_INITIALIZED)".
class RendererError : public std::runtime_error {
  public:
    RendererError(std::string_view source, std::string_view message);
};

class Renderer {
  public:
    virtual ~Renderer() = default;

    // Sets the frame size in pixels; the frame's contents are undefined until clear().
    virtual void resize(int width, int height) = 0;
    // Black background, depth 1 everywhere.
    virtual void clear() = 0;
    // Depth 1 everywhere, colours kept: what is drawn next covers what is there (a finer level of
    // detail over a coarser one, section 4.1.4).
    virtual void clear_depth() = 0;
    // Adds `mesh` to the current frame without clearing it, so a caller can draw only the groups
    // that changed since the last frame.
    virtual void draw(const Mesh& mesh, const glm::mat4& view, const glm::mat4& projection) = 0;
    // Colour (RGBA8) and window depth of the frame, row 0 at the top.
    virtual void read_back(Image& out) = 0;
    // The same for `rect` of the frame only (x, y from the top-left; inside the frame), so a
    // caller that needs a region does not copy the whole frame.
    virtual void read_back(Image& out, const PixelRect& rect) = 0;
    // Sizes `covered` to `rect` and writes covered[y * rect.width + x] = 1 where something is
    // drawn at pixel (rect.x + x, rect.y + y) (depth below 1), else 0: what a ray order needs,
    // without the colour. This default reads both back; a back end may read the depth alone.
    virtual void read_coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect);
    // Waits until everything drawn so far is in the frame (for honest stage timings).
    virtual void finish() = 0;
    // Starts putting everything drawn so far into the frame without waiting for it (a present
    // that lets the caller go on extracting while the rasteriser or GPU draws): finished() then
    // says when it is there. A back end without fences waits here, as finish() does.
    virtual void flush() { finish(); }
    // Whether everything drawn before the last flush() is in the frame (true when no flush() is
    // outstanding); with `wait`, waits until it is and returns true.
    virtual bool finished(bool /*wait*/) { return true; }
    virtual std::string_view name() const = 0;
};

// backend is "osmesa" or "egl". Throws RendererError when the back end is unknown or its context
// cannot be created.
std::unique_ptr<Renderer> make_renderer(std::string_view backend);

// Mesa compiles its shader variants on the first draw (about 25 ms in llvmpipe), and sets up its
// read-back paths on their first use. An interactive viewer pays that once at start-up, not in
// every frame: this draws one triangle, reads it back in every way a frame is read (whole, a
// rectangle, coverage) and draws again over a cleared depth, before any frame is timed (the owner
// of a renderer that times frames calls it; scripts/vtk_reference.py warms VTK alike). A wall
// rank's first help job costs about 0.7 ms after it against 2-2.5 ms after one draw alone
// (isowall-bench-frames).
void warm_up(Renderer& renderer);

// `mesh` drawn alone into `renderer` at `view`'s size and read back: the full surface's image,
// which a progressive frame's final image is measured against.
Image draw_alone(Renderer& renderer, const Mesh& mesh, const FrameView& view);

}  // namespace isowall
