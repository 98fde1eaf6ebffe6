// EGL back end: a headless OpenGL context with no surface. Mesa offers the surfaceless platform;
// vendor drivers (NVIDIA) offer the device platform; the default display is the last resort.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "render/backends.h"
#include "render/gl_core.h"

namespace isowall {
namespace {

constexpr std::string_view kEglName = "egl";

GlProc egl_loader(const char* name) {
    return eglGetProcAddress(name);
}

std::string egl_error_name(EGLint error) {
    switch (error) {
        case EGL_SUCCESS:
            return "EGL_SUCCESS";
        case EGL_NOT_INITIALIZED:
            return "EGL_NOT_INITIALIZED";
        case EGL_BAD_ACCESS:
            return "EGL_BAD_ACCESS";
        case EGL_BAD_ALLOC:
            return "EGL_BAD_ALLOC";
        case EGL_BAD_ATTRIBUTE:
            return "EGL_BAD_ATTRIBUTE";
        case EGL_BAD_CONTEXT:
            return "EGL_BAD_CONTEXT";
        case EGL_BAD_CONFIG:
            return "EGL_BAD_CONFIG";
        case EGL_BAD_CURRENT_SURFACE:
            return "EGL_BAD_CURRENT_SURFACE";
        case EGL_BAD_DISPLAY:
            return "EGL_BAD_DISPLAY";
        case EGL_BAD_SURFACE:
            return "EGL_BAD_SURFACE";
        case EGL_BAD_MATCH:
            return "EGL_BAD_MATCH";
        case EGL_BAD_PARAMETER:
            return "EGL_BAD_PARAMETER";
        case EGL_BAD_NATIVE_PIXMAP:
            return "EGL_BAD_NATIVE_PIXMAP";
        case EGL_BAD_NATIVE_WINDOW:
            return "EGL_BAD_NATIVE_WINDOW";
        case EGL_CONTEXT_LOST:
            return "EGL_CONTEXT_LOST";
        default:
            return "EGL error " + std::to_string(error);
    }
}

[[noreturn]] void fail(std::string_view call) {
    throw RendererError(kEglName,
                        std::string(call) + " failed (" + egl_error_name(eglGetError()) + ")");
}

bool has_extension(const char* list, std::string_view name) {
    if (list == nullptr) return false;
    for (std::string_view rest(list); !rest.empty();) {
        const std::size_t end = std::min(rest.find(' '), rest.size());
        if (rest.substr(0, end) == name) return true;
        rest.remove_prefix(std::min(end + 1, rest.size()));
    }
    return false;
}

// eglTerminate ends a display for the whole process, not per caller, so two renderers on the
// same display count their users and only the last one terminates it.
class DisplayUsers {
  public:
    static void acquire(EGLDisplay display) {
        std::lock_guard lock(mutex());
        ++counts()[display];
    }
    static void release(EGLDisplay display) {
        std::lock_guard lock(mutex());
        if (--counts()[display] > 0) return;
        counts().erase(display);
        eglTerminate(display);
    }

  private:
    static std::mutex& mutex() {
        static std::mutex m;
        return m;
    }
    static std::map<EGLDisplay, int>& counts() {
        static std::map<EGLDisplay, int> c;
        return c;
    }
};

// The candidate displays in order of preference.
std::vector<EGLDisplay> candidate_displays() {
    std::vector<EGLDisplay> displays;
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
        eglGetProcAddress("eglGetPlatformDisplayEXT"));
    // ISOWALL_EGL_DEVICE=N picks the N-th EGL device (one GPU per rank on a multi-GPU node, e.g.
    // set from OMPI_COMM_WORLD_LOCAL_RANK in a launch wrapper); it must exist.
    if (const char* want = std::getenv("ISOWALL_EGL_DEVICE"); want && *want) {
        auto query_devices =
            reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        EGLDeviceEXT devices[16];
        EGLint count = 0;
        if (get_platform_display == nullptr || query_devices == nullptr ||
            !query_devices(16, devices, &count))
            fail("ISOWALL_EGL_DEVICE: eglQueryDevicesEXT (no EGL device platform)");
        char* end = nullptr;
        const long n = std::strtol(want, &end, 10);
        if (*end != '\0' || n < 0 || n >= count)
            throw RendererError(kEglName, "ISOWALL_EGL_DEVICE=" + std::string(want) +
                                              ": expected a device index from 0 to " +
                                              std::to_string(count - 1));
        EGLDisplay d = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[n], nullptr);
        if (d == EGL_NO_DISPLAY)
            fail("eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, device " + std::string(want) +
                 ")");
        displays.push_back(d);
        return displays;
    }
    if (get_platform_display != nullptr) {
        if (has_extension(client, "EGL_MESA_platform_surfaceless")) {
            EGLDisplay d =
                get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
            if (d != EGL_NO_DISPLAY) displays.push_back(d);
        }
        auto query_devices =
            reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        if (has_extension(client, "EGL_EXT_platform_device") && query_devices != nullptr) {
            EGLDeviceEXT devices[8];
            EGLint count = 0;
            if (query_devices(8, devices, &count)) {
                for (EGLint i = 0; i < count; ++i) {
                    EGLDisplay d =
                        get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
                    if (d != EGL_NO_DISPLAY) displays.push_back(d);
                }
            }
        }
    }
    EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    if (d != EGL_NO_DISPLAY) displays.push_back(d);
    return displays;
}

EGLDisplay initialize_display() {
    const std::vector<EGLDisplay> displays = candidate_displays();
    if (displays.empty()) fail("eglGetPlatformDisplayEXT/eglGetDisplay");
    for (EGLDisplay d : displays) {
        if (eglInitialize(d, nullptr, nullptr)) {
            DisplayUsers::acquire(d);
            return d;
        }
    }
    fail("eglInitialize");
}

class EglRenderer final : public GlRenderer {
  public:
    EglRenderer() : display_(initialize_display()) {
        try {
            create_context();
            make_current();
            core_ = std::make_unique<GlCore>(kEglName, egl_loader);
        } catch (...) {
            release();
            throw;
        }
    }

    ~EglRenderer() override { release(); }

    EglRenderer(const EglRenderer&) = delete;
    EglRenderer& operator=(const EglRenderer&) = delete;

    std::string_view name() const override { return kEglName; }

  private:
    void create_context() {
        if (!eglBindAPI(EGL_OPENGL_API)) fail("eglBindAPI(EGL_OPENGL_API)");
        const char* extensions = eglQueryString(display_, EGL_EXTENSIONS);
        if (!has_extension(extensions, "EGL_KHR_surfaceless_context"))
            throw RendererError(kEglName, "display lacks EGL_KHR_surfaceless_context");
        // Without a surface the config only matters for its renderable type; skip it where the
        // driver allows.
        EGLConfig config = EGL_NO_CONFIG_KHR;
        if (!has_extension(extensions, "EGL_KHR_no_config_context")) {
            const EGLint wanted[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0,
                                     EGL_NONE};
            EGLint count = 0;
            if (!eglChooseConfig(display_, wanted, &config, 1, &count) || count < 1)
                fail("eglChooseConfig(EGL_OPENGL_BIT)");
        }
        const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                     3,
                                     EGL_CONTEXT_MINOR_VERSION,
                                     3,
                                     EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                     EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                     EGL_NONE};
        context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, attributes);
        if (context_ == EGL_NO_CONTEXT) fail("eglCreateContext(OpenGL 3.3 core)");
    }

    // Every call makes the context current: another renderer (OSMesa or EGL) may have taken the
    // thread since the last call.
    void make_current() override {
        if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
            fail("eglMakeCurrent");
    }

    // Frees GL objects while the context is current, then the context and our display use. Never
    // throws: it runs from the destructor.
    void release() noexcept {
        if (context_ != EGL_NO_CONTEXT) {
            if (eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
                core_.reset();
                eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            }
            eglDestroyContext(display_, context_);
            context_ = EGL_NO_CONTEXT;
        }
        DisplayUsers::release(display_);
    }

    EGLDisplay display_;
    EGLContext context_ = EGL_NO_CONTEXT;
};

}  // namespace

std::unique_ptr<Renderer> make_egl_renderer() {
    return std::make_unique<EglRenderer>();
}

}  // namespace isowall
