// OSMesa back end: a software context with no window system at all. Mesa needs a colour buffer to
// make the context current, so it gets a 1x1 dummy; all drawing goes to GlCore's framebuffer.
#include <GL/osmesa.h>

#include <array>
#include <memory>

#include "render/backends.h"
#include "render/gl_core.h"

namespace isowall {
namespace {

constexpr std::string_view kOsmesaName = "osmesa";

GlProc osmesa_loader(const char* name) {
    return OSMesaGetProcAddress(name);
}

OSMesaContext create_context() {
    const int core[] = {OSMESA_FORMAT,
                        OSMESA_RGBA,
                        OSMESA_DEPTH_BITS,
                        0,
                        OSMESA_PROFILE,
                        OSMESA_CORE_PROFILE,
                        OSMESA_CONTEXT_MAJOR_VERSION,
                        3,
                        OSMESA_CONTEXT_MINOR_VERSION,
                        3,
                        0};
    if (OSMesaContext ctx = OSMesaCreateContextAttribs(core, nullptr)) return ctx;
    // Older Mesa builds offer no core profile; a compatibility context of 3.3 or later runs the
    // same shaders, and GlCore checks the version it gets.
    const int compat[] = {
        OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_PROFILE, OSMESA_COMPAT_PROFILE, 0};
    if (OSMesaContext ctx = OSMesaCreateContextAttribs(compat, nullptr)) return ctx;
    throw RendererError(kOsmesaName,
                        "OSMesaCreateContextAttribs failed (no core 3.3 or compat context)");
}

class OsmesaRenderer final : public GlRenderer {
  public:
    OsmesaRenderer() : context_(create_context()) {
        try {
            make_current();
            core_ = std::make_unique<GlCore>(kOsmesaName, osmesa_loader);
        } catch (...) {
            OSMesaDestroyContext(context_);
            throw;
        }
    }

    ~OsmesaRenderer() override {
        // GlCore frees GL objects, which needs this context current; a failure here must not
        // escape a destructor, and destroying the context frees them anyway.
        if (OSMesaMakeCurrent(context_, dummy_.data(), GL_UNSIGNED_BYTE, 1, 1)) core_.reset();
        OSMesaDestroyContext(context_);
    }

    OsmesaRenderer(const OsmesaRenderer&) = delete;
    OsmesaRenderer& operator=(const OsmesaRenderer&) = delete;

    std::string_view name() const override { return kOsmesaName; }

  private:
    // Every call makes the context current: another renderer (OSMesa or EGL) may have taken the
    // thread since the last call.
    void make_current() override {
        if (!OSMesaMakeCurrent(context_, dummy_.data(), GL_UNSIGNED_BYTE, 1, 1))
            throw RendererError(kOsmesaName, "OSMesaMakeCurrent failed");
    }

    OSMesaContext context_;
    std::array<unsigned char, 4> dummy_{};
};

}  // namespace

std::unique_ptr<Renderer> make_osmesa_renderer() {
    return std::make_unique<OsmesaRenderer>();
}

}  // namespace isowall
