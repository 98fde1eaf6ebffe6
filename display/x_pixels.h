#pragma once
// RGBA8 images to and from the pixels of an X image (ZPixmap of a TrueColor visual), whatever
// the order of its channels. Separate from the window so it is tested without a display.
#include <X11/Xlib.h>
#include <X11/Xutil.h>

#include <cstdint>

#include "core/image.h"

namespace isowall {

// Where each 8-bit channel sits in a pixel value: shift of its mask's lowest bit.
struct PixelFormat {
    int red_shift = 16, green_shift = 8, blue_shift = 0;
    static PixelFormat from_masks(unsigned long red, unsigned long green, unsigned long blue);
};

// The top-left of `src` into `dst` (dst's size; src must be at least as large).
void pack_pixels(const Image& src, const PixelFormat& f, XImage& dst);
// All of `src` into `dst` (resized; alpha 255; depth empty).
void unpack_pixels(XImage& src, const PixelFormat& f, Image& dst);

}  // namespace isowall
