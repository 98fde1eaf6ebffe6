#include "display/x_window.h"

#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/extensions/XShm.h>
#include <poll.h>
#include <sys/ipc.h>
#include <sys/shm.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <mutex>

#include "display/x_pixels.h"

namespace isowall {
namespace {

// How long a window may take to be mapped before the display counts as unusable.
constexpr double kMapTimeoutS = 10;

// Xlib reports protocol errors through one process-wide handler; a present or an MIT-SHM attach
// checks the flag around an XSync. Only this file installs it.
std::mutex g_error_mutex;
bool g_x_error = false;

int note_error(Display*, XErrorEvent*) {
    g_x_error = true;
    return 0;
}

// Runs `call` and reports whether the server refused it.
template <typename F>
bool x_ok(Display* dpy, F&& call) {
    std::lock_guard<std::mutex> lock(g_error_mutex);
    g_x_error = false;
    XErrorHandler old = XSetErrorHandler(note_error);
    call();
    XSync(dpy, False);
    XSetErrorHandler(old);
    return !g_x_error;
}

std::string quoted(const std::string& s) {
    return "\"" + s + "\"";
}

Display* open_display(const std::string& name) {
    if (name.empty())
        throw DisplayError(
            "no X display: --windows and --control need a display (set $DISPLAY "
            "or the wall file's display key)");
    Display* dpy = XOpenDisplay(name.c_str());
    if (!dpy)
        throw DisplayError("cannot open X display " + quoted(name) +
                           " (is an X server running there, and may we connect?)");
    return dpy;
}

}  // namespace

std::string resolve_display(const std::string& name) {
    if (!name.empty()) return name;
    const char* env = std::getenv("DISPLAY");
    return env ? std::string(env) : std::string();
}

struct XWindow::Impl {
    std::string name;
    Display* dpy = nullptr;
    int screen = 0;
    Visual* visual = nullptr;
    int depth = 0;
    Window window = 0;
    GC gc = nullptr;
    Atom delete_atom = 0;
    int width = 0, height = 0;
    PixelFormat format;
    // The frame buffer the server reads: shared memory when it can, else plain memory.
    XImage* image = nullptr;
    XShmSegmentInfo shm{};
    bool use_shm = false;
    bool allow_shm = true;

    ~Impl() {
        release_image();
        if (gc) XFreeGC(dpy, gc);
        if (window) XDestroyWindow(dpy, window);
        if (dpy) XCloseDisplay(dpy);
    }

    void release_image() {
        if (!image) return;
        if (use_shm) {
            XShmDetach(dpy, &shm);
            XSync(dpy, False);
            image->data = nullptr;
            shmdt(shm.shmaddr);
        }
        XDestroyImage(image);
        image = nullptr;
    }

    bool try_shm_image(int w, int h) {
        if (!XShmQueryExtension(dpy)) return false;
        image = XShmCreateImage(dpy, visual, depth, ZPixmap, nullptr, &shm, w, h);
        if (!image) return false;
        shm.shmid = shmget(IPC_PRIVATE, static_cast<std::size_t>(image->bytes_per_line) * h,
                           IPC_CREAT | 0600);
        if (shm.shmid < 0) {
            XDestroyImage(image);
            image = nullptr;
            return false;
        }
        shm.shmaddr = image->data = static_cast<char*>(shmat(shm.shmid, nullptr, 0));
        shm.readOnly = False;
        // A server on another host cannot attach: it answers BadAccess, and we draw without.
        const bool attached = x_ok(dpy, [&] { XShmAttach(dpy, &shm); });
        shmctl(shm.shmid, IPC_RMID, nullptr);
        if (!attached) {
            image->data = nullptr;
            shmdt(shm.shmaddr);
            XDestroyImage(image);
            image = nullptr;
            return false;
        }
        return true;
    }

    void ensure_image(int w, int h) {
        if (image && image->width == w && image->height == h) return;
        release_image();
        use_shm = allow_shm && try_shm_image(w, h);
        if (use_shm) return;
        image = XCreateImage(dpy, visual, depth, ZPixmap, 0, nullptr, w, h, 32, 0);
        if (!image) throw DisplayError("X display " + quoted(name) + ": XCreateImage failed");
        image->data =
            static_cast<char*>(std::calloc(static_cast<std::size_t>(image->bytes_per_line) * h, 1));
    }

    void wait_mapped() {
        const auto deadline =
            std::chrono::steady_clock::now() + std::chrono::duration<double>(kMapTimeoutS);
        for (;;) {
            while (XPending(dpy)) {
                XEvent e;
                XNextEvent(dpy, &e);
                if (e.type == MapNotify && e.xmap.window == window) return;
                if (e.type == ConfigureNotify) note_size(e.xconfigure.width, e.xconfigure.height);
            }
            if (std::chrono::steady_clock::now() > deadline)
                throw DisplayError("X display " + quoted(name) + ": the window was not mapped " +
                                   "within " + std::to_string(static_cast<int>(kMapTimeoutS)) +
                                   " s");
            pollfd p{ConnectionNumber(dpy), POLLIN, 0};
            ::poll(&p, 1, 50);
        }
    }

    void note_size(int w, int h) {
        width = w;
        height = h;
    }
};

XWindow::XWindow(const WindowOptions& o) : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.name = resolve_display(o.display);
    m.allow_shm = o.shared_memory;
    m.dpy = open_display(m.name);
    m.screen = DefaultScreen(m.dpy);
    m.visual = DefaultVisual(m.dpy, m.screen);
    m.depth = DefaultDepth(m.dpy, m.screen);
    if (m.visual->c_class != TrueColor || m.depth < 24)
        throw DisplayError("X display " + quoted(m.name) + ": screen " + std::to_string(m.screen) +
                           " is not 24-bit TrueColor (depth " + std::to_string(m.depth) + ")");
    m.format =
        PixelFormat::from_masks(m.visual->red_mask, m.visual->green_mask, m.visual->blue_mask);
    const Window root = RootWindow(m.dpy, m.screen);
    XSetWindowAttributes a{};
    a.background_pixel = BlackPixel(m.dpy, m.screen);
    a.override_redirect = o.fullscreen ? True : False;
    a.event_mask =
        StructureNotifyMask | ExposureMask |
        (o.input ? ButtonPressMask | ButtonReleaseMask | PointerMotionMask | KeyPressMask : 0);
    int w = o.fullscreen ? DisplayWidth(m.dpy, m.screen) : o.width;
    int h = o.fullscreen ? DisplayHeight(m.dpy, m.screen) : o.height;
    int x = 0, y = 0;
    using Part = WindowOptions::Part;
    if (o.fullscreen && (o.part == Part::left_half || o.part == Part::right_half)) {
        w /= 2;
        x = o.part == Part::right_half ? DisplayWidth(m.dpy, m.screen) - w : 0;
    }
    if (o.fullscreen && (o.part == Part::top_half || o.part == Part::bottom_half)) {
        h /= 2;
        y = o.part == Part::bottom_half ? DisplayHeight(m.dpy, m.screen) - h : 0;
    }
    m.window = XCreateWindow(m.dpy, root, x, y, static_cast<unsigned>(w), static_cast<unsigned>(h),
                             0, m.depth, InputOutput, m.visual,
                             CWBackPixel | CWOverrideRedirect | CWEventMask, &a);
    m.note_size(w, h);
    XStoreName(m.dpy, m.window, o.title.c_str());
    m.delete_atom = XInternAtom(m.dpy, "WM_DELETE_WINDOW", False);
    XSetWMProtocols(m.dpy, m.window, &m.delete_atom, 1);
    m.gc = XCreateGC(m.dpy, m.window, 0, nullptr);
    XMapRaised(m.dpy, m.window);
    m.wait_mapped();
}

XWindow::~XWindow() = default;

int XWindow::width() const {
    return impl_->width;
}
int XWindow::height() const {
    return impl_->height;
}
std::uint64_t XWindow::id() const {
    return impl_->window;
}
const std::string& XWindow::display_name() const {
    return impl_->name;
}
bool XWindow::shared_memory() const {
    return impl_->use_shm;
}

void XWindow::present(const Image& img, int x, int y) {
    Impl& m = *impl_;
    const int w = std::min(img.width, m.width - x), h = std::min(img.height, m.height - y);
    if (w <= 0 || h <= 0 || x < 0 || y < 0) return;
    m.ensure_image(w, h);
    pack_pixels(img, m.format, *m.image);
    if (m.use_shm)
        XShmPutImage(m.dpy, m.window, m.gc, m.image, 0, 0, x, y, static_cast<unsigned>(w),
                     static_cast<unsigned>(h), False);
    else
        XPutImage(m.dpy, m.window, m.gc, m.image, 0, 0, x, y, static_cast<unsigned>(w),
                  static_cast<unsigned>(h));
    XSync(m.dpy, False);
}

std::vector<WindowEvent> XWindow::poll() {
    Impl& m = *impl_;
    std::vector<WindowEvent> out;
    while (XPending(m.dpy)) {
        XEvent e;
        XNextEvent(m.dpy, &e);
        WindowEvent ev;
        switch (e.type) {
            case ButtonPress:
            case ButtonRelease:
                ev.kind =
                    e.type == ButtonPress ? WindowEvent::Kind::press : WindowEvent::Kind::release;
                ev.x = e.xbutton.x;
                ev.y = e.xbutton.y;
                ev.button = static_cast<int>(e.xbutton.button);
                break;
            case MotionNotify:
                ev.kind = WindowEvent::Kind::motion;
                ev.x = e.xmotion.x;
                ev.y = e.xmotion.y;
                break;
            case KeyPress: {
                ev.kind = WindowEvent::Kind::key;
                const KeySym sym = XLookupKeysym(&e.xkey, 0);
                const char* s = sym == NoSymbol ? nullptr : XKeysymToString(sym);
                if (!s) continue;
                ev.key = s;
                break;
            }
            case ClientMessage:
                if (static_cast<Atom>(e.xclient.data.l[0]) != m.delete_atom) continue;
                ev.kind = WindowEvent::Kind::close;
                break;
            case ConfigureNotify:
                m.note_size(e.xconfigure.width, e.xconfigure.height);
                continue;
            default:
                continue;
        }
        out.push_back(std::move(ev));
    }
    return out;
}

Image capture_window(const std::string& display, std::uint64_t id) {
    Display* dpy = open_display(resolve_display(display));
    Image out;
    XWindowAttributes a{};
    XImage* img = nullptr;
    const bool ok = x_ok(dpy, [&] {
        if (!XGetWindowAttributes(dpy, id, &a)) return;
        img = XGetImage(dpy, id, 0, 0, static_cast<unsigned>(a.width),
                        static_cast<unsigned>(a.height), AllPlanes, ZPixmap);
    });
    if (ok && img) {
        unpack_pixels(*img, PixelFormat::from_masks(img->red_mask, img->green_mask, img->blue_mask),
                      out);
    }
    if (img) XDestroyImage(img);
    XCloseDisplay(dpy);
    if (!ok || out.width == 0)
        throw DisplayError("X display " + quoted(display) + ": cannot read window " +
                           std::to_string(id));
    return out;
}

namespace {

Window find_named(Display* dpy, Window w, const std::string& title) {
    char* name = nullptr;
    if (XFetchName(dpy, w, &name) && name) {
        const bool match = title == name;
        XFree(name);
        XWindowAttributes a{};
        if (match && XGetWindowAttributes(dpy, w, &a) && a.map_state == IsViewable) return w;
    }
    Window root_ret = 0, parent = 0, *children = nullptr;
    unsigned n = 0;
    if (!XQueryTree(dpy, w, &root_ret, &parent, &children, &n)) return 0;
    Window found = 0;
    for (unsigned i = 0; i < n && !found; ++i) found = find_named(dpy, children[i], title);
    if (children) XFree(children);
    return found;
}

}  // namespace

std::uint64_t find_window(const std::string& display, const std::string& title) {
    Display* dpy = open_display(resolve_display(display));
    Window found = 0;
    x_ok(dpy, [&] { found = find_named(dpy, DefaultRootWindow(dpy), title); });
    XCloseDisplay(dpy);
    return found;
}

}  // namespace isowall
