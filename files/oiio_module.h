#pragma once
// OpenImageIO, loaded when the first image is read or written. Debian's OpenImageIO brings 261
// shared libraries (GDAL, OpenCV, OpenColorIO, codecs), whose loading took 0.53 s of the 0.69 s
// `isowall --help` took to start: every process paid it, each of a wall's ranks among them, and
// most never touch an image. So the program does not link OpenImageIO: the module
// isowall_oiio.so (files/oiio_plugin.cpp, built beside the program) does, and api() opens
// it with dlopen on first use. Every image and TIFF slice goes through the table below; the
// module throws nothing across it (an error is a false return and a message).
#include <cstddef>
#include <string>
#include <vector>

#include "core/image.h"

namespace isowall::oiio {

inline constexpr int kApiVersion = 1;

// The sample types a slice may hold that isowall reads, in the order of VoxelType
// (volume/volume.h; the TIFF reader checks it); other: any other, named in `format`.
enum class Sample { u8, i8, u16, i16, u32, i32, f32, f64, other };

// One page (subimage) of an image file, as OpenImageIO describes it.
struct PageInfo {
    int width = 0, height = 0, depth = 0, channels = 0;
    Sample sample = Sample::other;
    std::string format;                        // the sample type's name, for messages
    std::string description;                   // the ImageDescription tag ("" when none)
    float x_resolution = 0, y_resolution = 0;  // pixels per unit; 0 when not given
    std::string resolution_unit;               // "" when not given
};

struct Api {
    int version;
    // Whether OpenImageIO has a writer for `path`'s extension.
    bool (*can_write)(const std::string& path);
    // Encodes colour (RGBA where the format stores alpha, else RGB) or depth (one float channel
    // "Z") for `path`'s format. A writer that takes an I/O proxy encodes into `memory`, which the
    // caller writes to `temporary` through its checked writer; any other writes `temporary`
    // itself and leaves `memory` empty.
    bool (*encode_colour)(const std::string& path, const std::string& temporary, const Image& image,
                          std::vector<unsigned char>& memory, std::string& error);
    bool (*encode_depth)(const std::string& path, const std::string& temporary, const Image& image,
                         std::vector<unsigned char>& memory, std::string& error);
    bool (*read_colour)(const std::string& path, Image& out, std::string& error);
    bool (*read_depth)(const std::string& path, Image& out, std::string& error);
    // An image file for reading pages: null with `error` when OpenImageIO cannot open it. `format`
    // gets the reader's name ("tiff", "png", ...). Close with close_file.
    void* (*open_file)(const std::string& path, std::string& format, std::string& error);
    void (*close_file)(void* file);
    int (*page_count)(void* file);
    bool (*page_info)(void* file, int page, PageInfo& out);
    // One channel of `page` as `sample` into `out` (width * height samples).
    bool (*read_page)(void* file, int page, Sample sample, void* out, std::string& error);
};

// The module's table, loaded once (thread-safe). Throws std::runtime_error naming the module's
// path and the loader's message when it cannot be loaded. The module is looked for in
// $ISOWALL_OIIO_MODULE when set, else beside the running program, else where the build put it.
const Api& api();

}  // namespace isowall::oiio

// The module's one entry point.
extern "C" const isowall::oiio::Api* isowall_oiio_api();
