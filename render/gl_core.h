#pragma once
// The OpenGL 3.3 core work both back ends share: an off-screen framebuffer (RGBA8 colour and
// 24-bit depth renderbuffers), the headlight shader, mesh upload, drawing and read-back. A back
// end creates the context, makes it current and then forwards every call here; GlCore itself
// never switches contexts.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/image.h"
#include "core/mesh.h"
#include "render/renderer.h"

namespace isowall {

struct GlFunctions;
using GlProc = void (*)();
using GlLoader = GlProc (*)(const char* name);

class GlCore {
  public:
    // The back end's context must be current; `loader` fetches GL entry points from it and
    // `backend` prefixes every RendererError.
    GlCore(std::string_view backend, GlLoader loader);
    // Frees the GL objects, so the context must still be current.
    ~GlCore();
    GlCore(const GlCore&) = delete;
    GlCore& operator=(const GlCore&) = delete;

    void resize(int width, int height);
    int width() const { return width_; }
    int height() const { return height_; }
    void clear();
    void clear_depth();
    void draw(const Mesh& mesh, const glm::mat4& view, const glm::mat4& projection);
    void read_back(Image& out, const PixelRect& rect);
    // The depth of `rect` alone, as Renderer::read_coverage gives it.
    void read_coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect);
    void finish();
    // A fence after everything drawn so far, then glFlush: the rasteriser starts on it and this
    // returns at once (finished() tells when it is done). Replaces an earlier fence.
    void flush();
    // Whether the last flush()'s fence has passed (true when there is none); with `wait`, waits
    // for it.
    bool finished(bool wait);

  private:
    // A frame with under 1/kShrinkFactor of its buffers' area gets buffers of its own size.
    static constexpr double kShrinkFactor = 8;
    [[noreturn]] void fail(std::string_view call, std::string_view detail) const;
    // Throws naming `call` when GL has recorded an error since the last check.
    void check(std::string_view call) const;
    void require_size(std::string_view call) const;
    // Binds the frame and checks that `rect` lies inside it.
    void bind_rect(std::string_view call, const PixelRect& rect);
    unsigned compile_shader(unsigned type, const char* source);
    void bind_frame();

    std::string backend_;
    std::unique_ptr<GlFunctions> gl_;
    int storage_width_ = 0, storage_height_ = 0;  // of the renderbuffers, >= the frame
    int width_ = 0;
    int height_ = 0;
    unsigned framebuffer_ = 0;
    unsigned colour_buffer_ = 0;
    unsigned depth_buffer_ = 0;
    unsigned program_ = 0;
    unsigned vertex_array_ = 0;
    unsigned position_buffer_ = 0;
    unsigned normal_buffer_ = 0;
    unsigned colour_buffer_attr_ = 0;  // vertex colours (colour_buffer_ is the frame's)
    unsigned index_buffer_ = 0;
    int model_view_location_ = -1;
    int projection_location_ = -1;
    int normal_matrix_location_ = -1;
    int orthographic_location_ = -1;
    int coloured_location_ = -1;
    std::vector<std::uint32_t> depth_scratch_;  // read_coverage's rows, as GL gives them
    void* fence_ = nullptr;                     // flush()'s GLsync, until it has passed
};

// The Renderer calls every GL back end shares: make the back end's context current, then let
// GlCore do the work. A back end supplies the context (make_current) and creates core_.
class GlRenderer : public Renderer {
  public:
    void resize(int width, int height) override {
        make_current();
        core_->resize(width, height);
    }
    void clear() override {
        make_current();
        core_->clear();
    }
    void clear_depth() override {
        make_current();
        core_->clear_depth();
    }
    void draw(const Mesh& mesh, const glm::mat4& view, const glm::mat4& projection) override {
        make_current();
        core_->draw(mesh, view, projection);
    }
    void read_back(Image& out) override {
        make_current();
        core_->read_back(out, core_frame());
    }
    void read_back(Image& out, const PixelRect& rect) override {
        make_current();
        core_->read_back(out, rect);
    }
    void read_coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) override {
        make_current();
        core_->read_coverage(covered, rect);
    }
    void finish() override {
        make_current();
        core_->finish();
    }
    void flush() override {
        make_current();
        core_->flush();
    }
    bool finished(bool wait) override {
        make_current();
        return core_->finished(wait);
    }

  protected:
    virtual void make_current() = 0;
    PixelRect core_frame() const { return {0, 0, core_->width(), core_->height()}; }
    std::unique_ptr<GlCore> core_;
};

}  // namespace isowall
