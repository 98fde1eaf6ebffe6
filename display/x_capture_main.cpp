// isowall-xcapture: a window of an X display as a PNG, for screenshots and tests.
//   isowall-xcapture DISPLAY TITLE OUT.png    the mapped window named TITLE ("root": the screen)
#include <cstdio>
#include <exception>
#include <string>

#include <X11/Xlib.h>

#include "display/x_window.h"
#include "files/image_io.h"

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: isowall-xcapture DISPLAY TITLE|root OUT.png\n");
        return 2;
    }
    try {
        const std::string display = argv[1], title = argv[2];
        std::uint64_t id = 0;
        if (title == "root") {
            Display* dpy = XOpenDisplay(display.c_str());
            if (!dpy) throw isowall::DisplayError("cannot open X display \"" + display + "\"");
            id = DefaultRootWindow(dpy);
            XCloseDisplay(dpy);
        } else {
            id = isowall::find_window(display, title);
        }
        if (!id)
            throw isowall::DisplayError("no mapped window named \"" + title + "\" on " + display);
        isowall::write_image(argv[3], isowall::capture_window(display, id));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "isowall-xcapture: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
