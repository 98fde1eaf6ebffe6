#include "render/gl_core.h"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>

#include "render/gl_functions.h"
#include "render/renderer.h"
#include "render/shader_sources.h"

namespace isowall {
namespace {

// The surface's shaders, one definition for this renderer and the page (render/shaders/), as
// GLSL 3.30 core.
const std::string kVertexShader = std::string("#version 330 core\n") + shaders::kSurfaceVert;
const std::string kFragmentShader = std::string("#version 330 core\n") + shaders::kHeadlightFrag;

std::string gl_error_name(GLenum error) {
    switch (error) {
        case GL_INVALID_ENUM:
            return "GL_INVALID_ENUM";
        case GL_INVALID_VALUE:
            return "GL_INVALID_VALUE";
        case GL_INVALID_OPERATION:
            return "GL_INVALID_OPERATION";
        case GL_INVALID_FRAMEBUFFER_OPERATION:
            return "GL_INVALID_FRAMEBUFFER_OPERATION";
        case GL_OUT_OF_MEMORY:
            return "GL_OUT_OF_MEMORY";
        default:
            return "GL error " + std::to_string(error);
    }
}

// Flips rows in place: GL reads bottom-up, Image stores the top row first.
template <typename T>
void flip_rows(std::vector<T>& pixels, std::size_t row_length, int height) {
    for (int top = 0, bottom = height - 1; top < bottom; ++top, --bottom) {
        auto a = pixels.begin() + static_cast<std::ptrdiff_t>(top * row_length);
        auto b = pixels.begin() + static_cast<std::ptrdiff_t>(bottom * row_length);
        std::swap_ranges(a, a + static_cast<std::ptrdiff_t>(row_length), b);
    }
}

}  // namespace

GlCore::GlCore(std::string_view backend, GlLoader loader)
    : backend_(backend), gl_(std::make_unique<GlFunctions>()) {
    if (std::string missing = gl_->load(loader); !missing.empty())
        fail("GetProcAddress(" + missing + ")", "entry point not found");

    GLint major = 0, minor = 0;
    gl_->GetIntegerv(GL_MAJOR_VERSION, &major);
    gl_->GetIntegerv(GL_MINOR_VERSION, &minor);
    if (major * 10 + minor < 33) {
        const auto* version = reinterpret_cast<const char*>(gl_->GetString(GL_VERSION));
        fail("glGetIntegerv(GL_MAJOR_VERSION)",
             "OpenGL 3.3 required, context has " + std::string(version ? version : "none"));
    }

    const GLuint vertex = compile_shader(GL_VERTEX_SHADER, kVertexShader.c_str());
    const GLuint fragment = compile_shader(GL_FRAGMENT_SHADER, kFragmentShader.c_str());
    program_ = gl_->CreateProgram();
    gl_->AttachShader(program_, vertex);
    gl_->AttachShader(program_, fragment);
    gl_->LinkProgram(program_);
    // The program keeps the compiled code; the shader objects are only needed for linking.
    gl_->DeleteShader(vertex);
    gl_->DeleteShader(fragment);
    GLint linked = GL_FALSE;
    gl_->GetProgramiv(program_, GL_LINK_STATUS, &linked);
    if (linked != GL_TRUE) {
        std::string log(4096, '\0');
        GLsizei length = 0;
        gl_->GetProgramInfoLog(program_, static_cast<GLsizei>(log.size()), &length, log.data());
        log.resize(static_cast<std::size_t>(length));
        fail("glLinkProgram", log);
    }
    model_view_location_ = gl_->GetUniformLocation(program_, "model_view");
    projection_location_ = gl_->GetUniformLocation(program_, "projection");
    normal_matrix_location_ = gl_->GetUniformLocation(program_, "normal_matrix");
    orthographic_location_ = gl_->GetUniformLocation(program_, "orthographic");
    coloured_location_ = gl_->GetUniformLocation(program_, "coloured");

    // One set of buffers, refilled by every draw(): meshes arrive once per frame and change
    // between frames, so caching per mesh would buy nothing yet.
    gl_->GenVertexArrays(1, &vertex_array_);
    gl_->BindVertexArray(vertex_array_);
    gl_->GenBuffers(1, &position_buffer_);
    gl_->GenBuffers(1, &normal_buffer_);
    gl_->GenBuffers(1, &colour_buffer_attr_);
    gl_->GenBuffers(1, &index_buffer_);
    gl_->BindBuffer(GL_ARRAY_BUFFER, position_buffer_);
    gl_->VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
    gl_->EnableVertexAttribArray(0);
    gl_->BindBuffer(GL_ARRAY_BUFFER, normal_buffer_);
    gl_->VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
    gl_->EnableVertexAttribArray(1);
    // Colours, when a mesh has them (draw enables the array then): bytes, normalised to [0, 1].
    gl_->BindBuffer(GL_ARRAY_BUFFER, colour_buffer_attr_);
    gl_->VertexAttribPointer(2, 3, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(glm::u8vec3), nullptr);
    // The element buffer binding is part of the vertex array's state.
    gl_->BindBuffer(GL_ELEMENT_ARRAY_BUFFER, index_buffer_);
    gl_->BindVertexArray(0);

    gl_->GenFramebuffers(1, &framebuffer_);
    gl_->GenRenderbuffers(1, &colour_buffer_);
    gl_->GenRenderbuffers(1, &depth_buffer_);
    check("GlCore setup");
}

GlCore::~GlCore() {
    if (fence_) gl_->DeleteSync(static_cast<GLsync>(fence_));
    gl_->DeleteFramebuffers(1, &framebuffer_);
    gl_->DeleteRenderbuffers(1, &colour_buffer_);
    gl_->DeleteRenderbuffers(1, &depth_buffer_);
    gl_->DeleteBuffers(1, &position_buffer_);
    gl_->DeleteBuffers(1, &normal_buffer_);
    gl_->DeleteBuffers(1, &colour_buffer_attr_);
    gl_->DeleteBuffers(1, &index_buffer_);
    gl_->DeleteVertexArrays(1, &vertex_array_);
    gl_->DeleteProgram(program_);
}

void GlCore::fail(std::string_view call, std::string_view detail) const {
    throw RendererError(backend_, std::string(call) + " failed (" + std::string(detail) + ")");
}

void GlCore::check(std::string_view call) const {
    const GLenum error = gl_->GetError();
    if (error == GL_NO_ERROR) return;
    // Drain the remaining flags so the next check reports only its own calls.
    while (gl_->GetError() != GL_NO_ERROR) {
    }
    fail(call, gl_error_name(error));
}

void GlCore::require_size(std::string_view call) const {
    if (width_ == 0) fail(call, "resize() has not been called");
}

GLuint GlCore::compile_shader(GLenum type, const char* source) {
    const GLuint shader = gl_->CreateShader(type);
    gl_->ShaderSource(shader, 1, &source, nullptr);
    gl_->CompileShader(shader);
    GLint compiled = GL_FALSE;
    gl_->GetShaderiv(shader, GL_COMPILE_STATUS, &compiled);
    if (compiled != GL_TRUE) {
        std::string log(4096, '\0');
        GLsizei length = 0;
        gl_->GetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), &length, log.data());
        log.resize(static_cast<std::size_t>(length));
        gl_->DeleteShader(shader);
        fail(type == GL_VERTEX_SHADER ? "glCompileShader(vertex)" : "glCompileShader(fragment)",
             log);
    }
    return shader;
}

void GlCore::resize(int width, int height) {
    GLint max_size = 0;
    gl_->GetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
    if (width <= 0 || height <= 0 || width > max_size || height > max_size) {
        fail("resize(" + std::to_string(width) + ", " + std::to_string(height) + ")",
             "each side must be in [1, " + std::to_string(max_size) + "]");
    }
    width_ = width;
    height_ = height;
    // The frame is the bottom-left width x height of its buffers (the viewport), so a smaller
    // frame reuses them: a wall rank resizes its help frame for every region it fills, and
    // reallocating costs llvmpipe fresh pages each time. But a clear clears the whole buffers in
    // a software rasteriser (and a scissored one is slower still), so a frame far smaller than
    // them gets buffers of its own size: after one 1024x768 region, each 128x96 region's clear
    // and read-back cost 650 us instead of 56 (llvmpipe, one thread).
    const bool fits = width <= storage_width_ && height <= storage_height_;
    const double area = double(width) * double(height);
    const bool far_smaller =
        area * kShrinkFactor <= double(storage_width_) * double(storage_height_);
    if (fits && !far_smaller) return;
    storage_width_ = fits ? width : std::max(width, storage_width_);
    storage_height_ = fits ? height : std::max(height, storage_height_);
    gl_->BindRenderbuffer(GL_RENDERBUFFER, colour_buffer_);
    gl_->RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, storage_width_, storage_height_);
    gl_->BindRenderbuffer(GL_RENDERBUFFER, depth_buffer_);
    gl_->RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, storage_width_,
                             storage_height_);
    gl_->BindRenderbuffer(GL_RENDERBUFFER, 0);
    check("glRenderbufferStorage");

    gl_->BindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
    gl_->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                 colour_buffer_);
    gl_->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                                 depth_buffer_);
    const GLenum status = gl_->CheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        fail("glCheckFramebufferStatus", "status " + std::to_string(status));
}

void GlCore::bind_frame() {
    // Bound on every call: another GlCore, or the caller, may have changed the bindings in a
    // context that shares this thread.
    gl_->BindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
    const GLenum attachment = GL_COLOR_ATTACHMENT0;
    gl_->DrawBuffers(1, &attachment);
    gl_->ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl_->Viewport(0, 0, width_, height_);
}

void GlCore::clear() {
    require_size("clear");
    bind_frame();
    gl_->ClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    gl_->ClearDepth(1.0);
    gl_->DepthMask(GL_TRUE);
    gl_->Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    // Started at once: a software rasteriser (llvmpipe) clears the frame's tiles on its own
    // threads while the caller works on, instead of at the frame's first flush (about 2 ms at
    // 1600x1200, when the engine waits for its first coverage).
    gl_->Flush();
    check("glClear");
}

void GlCore::clear_depth() {
    require_size("clear_depth");
    bind_frame();
    gl_->ClearDepth(1.0);
    gl_->DepthMask(GL_TRUE);
    gl_->Clear(GL_DEPTH_BUFFER_BIT);
    check("glClear");
}

void GlCore::draw(const Mesh& mesh, const glm::mat4& view, const glm::mat4& projection) {
    require_size("draw");
    if (mesh.normals.size() != mesh.positions.size()) {
        fail("draw", "mesh has " + std::to_string(mesh.normals.size()) + " normals for " +
                         std::to_string(mesh.positions.size()) + " positions");
    }
    if (!mesh.colours.empty() && mesh.colours.size() != mesh.positions.size()) {
        fail("draw", "mesh has " + std::to_string(mesh.colours.size()) + " colours for " +
                         std::to_string(mesh.positions.size()) + " positions");
    }
    if (mesh.empty()) return;
    bind_frame();
    gl_->Enable(GL_DEPTH_TEST);
    gl_->DepthFunc(GL_LESS);
    gl_->DepthMask(GL_TRUE);
    // Isosurfaces of clipped volumes are open, so both sides must be drawn.
    gl_->Disable(GL_CULL_FACE);

    gl_->UseProgram(program_);
    const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(view)));
    gl_->UniformMatrix4fv(model_view_location_, 1, GL_FALSE, glm::value_ptr(view));
    gl_->UniformMatrix4fv(projection_location_, 1, GL_FALSE, glm::value_ptr(projection));
    gl_->UniformMatrix3fv(normal_matrix_location_, 1, GL_FALSE, glm::value_ptr(normal_matrix));
    // A perspective matrix copies -z into w; an orthographic one leaves w at 1.
    gl_->Uniform1i(orthographic_location_, projection[2][3] == 0.0f ? 1 : 0);
    const bool coloured = !mesh.colours.empty();
    gl_->Uniform1i(coloured_location_, coloured ? 1 : 0);

    const auto bytes = [](const auto& v) {
        return static_cast<GLsizeiptr>(v.size() * sizeof(v[0]));
    };
    gl_->BindVertexArray(vertex_array_);
    gl_->BindBuffer(GL_ARRAY_BUFFER, position_buffer_);
    gl_->BufferData(GL_ARRAY_BUFFER, bytes(mesh.positions), mesh.positions.data(), GL_STREAM_DRAW);
    gl_->BindBuffer(GL_ARRAY_BUFFER, normal_buffer_);
    gl_->BufferData(GL_ARRAY_BUFFER, bytes(mesh.normals), mesh.normals.data(), GL_STREAM_DRAW);
    if (coloured) {
        gl_->BindBuffer(GL_ARRAY_BUFFER, colour_buffer_attr_);
        gl_->BufferData(GL_ARRAY_BUFFER, bytes(mesh.colours), mesh.colours.data(), GL_STREAM_DRAW);
        gl_->EnableVertexAttribArray(2);
    } else {
        gl_->DisableVertexAttribArray(2);
    }
    gl_->BufferData(GL_ELEMENT_ARRAY_BUFFER, bytes(mesh.indices), mesh.indices.data(),
                    GL_STREAM_DRAW);
    check("glBufferData");
    gl_->DrawElements(GL_TRIANGLES, static_cast<GLsizei>(mesh.indices.size()), GL_UNSIGNED_INT,
                      nullptr);
    gl_->BindVertexArray(0);
    gl_->UseProgram(0);
    check("glDrawElements");
}

void GlCore::finish() {
    gl_->Finish();
    check("glFinish");
    // Everything is in the frame now, the fenced commands too.
    if (fence_) gl_->DeleteSync(static_cast<GLsync>(fence_));
    fence_ = nullptr;
}

void GlCore::flush() {
    if (fence_) gl_->DeleteSync(static_cast<GLsync>(fence_));
    fence_ = gl_->FenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    if (fence_ == nullptr) fail("glFenceSync", "no fence");
    gl_->Flush();
    check("glFlush");
}

bool GlCore::finished(bool wait) {
    if (!fence_) return true;
    // A second at a time, so a wait that never ends is an error rather than a hang.
    constexpr GLuint64 kWaitNs = 1'000'000'000;
    GLenum r = gl_->ClientWaitSync(static_cast<GLsync>(fence_), 0, wait ? kWaitNs : 0);
    for (int tries = 1; wait && r == GL_TIMEOUT_EXPIRED && tries < 60; ++tries)
        r = gl_->ClientWaitSync(static_cast<GLsync>(fence_), 0, kWaitNs);
    if (r == GL_WAIT_FAILED) {
        check("glClientWaitSync");
        fail("glClientWaitSync", "GL_WAIT_FAILED");
    }
    if (wait && r == GL_TIMEOUT_EXPIRED) fail("glClientWaitSync", "the fence did not pass in 60 s");
    if (r == GL_TIMEOUT_EXPIRED) return false;
    gl_->DeleteSync(static_cast<GLsync>(fence_));
    fence_ = nullptr;
    return true;
}

void GlCore::bind_rect(std::string_view call, const PixelRect& rect) {
    require_size(call);
    if (rect.x < 0 || rect.y < 0 || rect.width < 0 || rect.height < 0 ||
        rect.x + rect.width > width_ || rect.y + rect.height > height_)
        fail(call, "the rect lies outside the frame");
    bind_frame();
}

void GlCore::read_coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) {
    bind_rect("read_coverage", rect);
    const auto w = static_cast<std::size_t>(rect.width);
    const auto h = static_cast<std::size_t>(rect.height);
    covered.resize(w * h);
    depth_scratch_.resize(w * h);
    if (covered.empty()) return;
    // The depth alone, as integers: the cleared depth 1 reads as the largest value (for the
    // head's 861x574 box in llvmpipe, 0.7-0.9 ms against 1.0-1.2 ms for colour and float depth).
    gl_->PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl_->ReadPixels(rect.x, height_ - rect.y - rect.height, rect.width, rect.height,
                    GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, depth_scratch_.data());
    check("glReadPixels(GL_DEPTH_COMPONENT)");
    for (std::size_t y = 0; y < h; ++y) {  // GL's rows from the bottom
        const std::uint32_t* from = depth_scratch_.data() + (h - 1 - y) * w;
        std::uint8_t* to = covered.data() + y * w;
        for (std::size_t x = 0; x < w; ++x) to[x] = from[x] != 0xFFFFFFFFu;
    }
}

void GlCore::read_back(Image& out, const PixelRect& rect) {
    bind_rect("read_back", rect);
    if (out.width != rect.width || out.height != rect.height ||
        out.pixel_count() != out.depth.size() || out.pixel_count() * 4 != out.rgba.size()) {
        out.resize(rect.width, rect.height);
    }
    // GL counts rows from the bottom.
    const int gl_y = height_ - rect.y - rect.height;
    gl_->PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl_->ReadPixels(rect.x, gl_y, rect.width, rect.height, GL_RGBA, GL_UNSIGNED_BYTE,
                    out.rgba.data());
    check("glReadPixels(GL_RGBA)");
    gl_->ReadPixels(rect.x, gl_y, rect.width, rect.height, GL_DEPTH_COMPONENT, GL_FLOAT,
                    out.depth.data());
    check("glReadPixels(GL_DEPTH_COMPONENT)");
    flip_rows(out.rgba, static_cast<std::size_t>(rect.width) * 4, rect.height);
    flip_rows(out.depth, static_cast<std::size_t>(rect.width), rect.height);
}

}  // namespace isowall
