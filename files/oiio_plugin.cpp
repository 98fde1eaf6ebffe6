// The module isowall_oiio.so: the one place that calls OpenImageIO (files/oiio_module.h says
// why it is a module). Nothing is thrown across its table: each function catches what OpenImageIO
// or the standard library throws and returns it as a message.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <array>
#include <exception>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "files/oiio_module.h"

namespace isowall::oiio {
namespace {

// Runs `f`, turning an exception into a false return with its message.
template <class F>
bool guarded(std::string& error, F&& f) {
    try {
        return f();
    } catch (const std::exception& e) {
        error = e.what();
    } catch (...) {
        error = "unknown error in OpenImageIO";
    }
    return false;
}

bool can_write(const std::string& path) {
    try {
        if (OIIO::ImageOutput::create(path)) return true;
    } catch (...) {
    }
    OIIO::geterror();  // clear OpenImageIO's pending message
    return false;
}

bool encode(const std::string& path, const std::string& temporary, const OIIO::ImageSpec& spec,
            const void* data, OIIO::stride_t xstride, std::vector<unsigned char>& memory,
            std::string& error) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) return error = OIIO::geterror(), false;
    // OpenImageIO's PNG writer over stdio drops a full disk's error and closes "fine" on a cut-off
    // file: where the writer takes an I/O proxy, it encodes into memory for the caller's writer.
    const bool in_memory = out->supports("ioproxy");
    OIIO::Filesystem::IOVecOutput proxy_buffer;
    OIIO::ImageSpec s = spec;
    if (in_memory) {
        OIIO::Filesystem::IOProxy* proxy = &proxy_buffer;
        s.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
    }
    if (!out->open(temporary, s) || !out->write_image(spec.format, data, xstride) || !out->close())
        return error = out->geterror(), false;
    memory.clear();
    if (in_memory) memory.assign(proxy_buffer.buffer().begin(), proxy_buffer.buffer().end());
    return true;
}

bool encode_colour(const std::string& path, const std::string& temporary, const Image& image,
                   std::vector<unsigned char>& memory, std::string& error) {
    return guarded(error, [&] {
        auto probe = OIIO::ImageOutput::create(path);
        if (!probe) return error = OIIO::geterror(), false;
        const int channels = probe->supports("alpha") ? 4 : 3;
        OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::UINT8);
        if (channels == 4) {
            spec.alpha_channel = 3;
            // Our alpha is straight, not premultiplied; without this OIIO would divide by it.
            spec.attribute("oiio:UnassociatedAlpha", 1);
        }
        // zlib's fastest level: a rendering is mostly flat background, which every level packs
        // about as well; the default (6) took 0.17 s of a 0.9 s frame's command at 1600x1200.
        spec.attribute("png:compressionLevel", 1);
        // With a 4-byte pixel stride, an RGB file simply skips each pixel's alpha.
        return encode(path, temporary, spec, image.rgba.data(), 4, memory, error);
    });
}

bool encode_depth(const std::string& path, const std::string& temporary, const Image& image,
                  std::vector<unsigned char>& memory, std::string& error) {
    return guarded(error, [&] {
        OIIO::ImageSpec spec(image.width, image.height, 1, OIIO::TypeDesc::FLOAT);
        spec.channelnames = {"Z"};
        spec.z_channel = 0;
        return encode(path, temporary, spec, image.depth.data(), sizeof(float), memory, error);
    });
}

bool read_colour(const std::string& path, Image& image, std::string& error) {
    return guarded(error, [&] {
        OIIO::ImageSpec config;
        // Keep alpha straight so that writing and reading back is exact.
        config.attribute("oiio:UnassociatedAlpha", 1);
        auto in = OIIO::ImageInput::open(path, &config);
        if (!in) return error = OIIO::geterror(), false;
        const OIIO::ImageSpec& spec = in->spec();
        const int channels = spec.nchannels;
        if (channels < 1 || channels > 4)
            return error = "expected 1 to 4 channels, found " + std::to_string(channels), false;
        std::vector<std::uint8_t> pixels(std::size_t(spec.width) * spec.height * channels);
        if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, pixels.data()))
            return error = in->geterror(), false;
        image.resize(spec.width, spec.height);
        for (std::size_t i = 0; i < image.pixel_count(); ++i) {
            const std::uint8_t* p = &pixels[i * channels];
            std::uint8_t* q = &image.rgba[i * 4];
            const bool grey = channels <= 2;
            q[0] = p[0];
            q[1] = grey ? p[0] : p[1];
            q[2] = grey ? p[0] : p[2];
            q[3] = channels == 2 ? p[1] : channels == 4 ? p[3] : 255;
        }
        return true;
    });
}

bool read_depth(const std::string& path, Image& image, std::string& error) {
    return guarded(error, [&] {
        auto in = OIIO::ImageInput::open(path);
        if (!in) return error = OIIO::geterror(), false;
        const OIIO::ImageSpec& spec = in->spec();
        image.resize(spec.width, spec.height);
        if (!in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, image.depth.data()))
            return error = in->geterror(), false;
        return true;
    });
}

void* open_file(const std::string& path, std::string& format, std::string& error) {
    void* file = nullptr;
    guarded(error, [&] {
        auto in = OIIO::ImageInput::open(path);
        if (!in) return error = OIIO::geterror(), false;
        format = in->format_name();
        file = in.release();
        return true;
    });
    return file;
}

void close_file(void* file) {
    delete static_cast<OIIO::ImageInput*>(file);
}

int page_count(void* file) {
    auto& in = *static_cast<OIIO::ImageInput*>(file);
    int n = 0;
    while (in.seek_subimage(n, 0)) ++n;
    in.geterror();  // seeking past the last page may leave a message we do not want
    return n;
}

// Each Sample but `other` beside OpenImageIO's base type.
constexpr std::array<std::pair<Sample, OIIO::TypeDesc::BASETYPE>, 8> kSamples{{
    {Sample::u8, OIIO::TypeDesc::UINT8},
    {Sample::i8, OIIO::TypeDesc::INT8},
    {Sample::u16, OIIO::TypeDesc::UINT16},
    {Sample::i16, OIIO::TypeDesc::INT16},
    {Sample::u32, OIIO::TypeDesc::UINT32},
    {Sample::i32, OIIO::TypeDesc::INT32},
    {Sample::f32, OIIO::TypeDesc::FLOAT},
    {Sample::f64, OIIO::TypeDesc::DOUBLE},
}};

Sample sample_of(OIIO::TypeDesc t) {
    for (const auto& [sample, base] : kSamples)
        if (t.basetype == base) return sample;
    return Sample::other;
}

OIIO::TypeDesc type_of(Sample s) {
    for (const auto& [sample, base] : kSamples)
        if (sample == s) return base;
    return OIIO::TypeDesc::UINT8;
}

bool page_info(void* file, int page, PageInfo& out) {
    std::string ignored;
    return guarded(ignored, [&] {
        auto& in = *static_cast<OIIO::ImageInput*>(file);
        const OIIO::ImageSpec spec = in.spec(page, 0);
        out.width = spec.width;
        out.height = spec.height;
        out.depth = spec.depth;
        out.channels = spec.nchannels;
        out.sample = sample_of(spec.format);
        out.format = spec.format.c_str();
        out.description = spec.get_string_attribute("ImageDescription");
        out.x_resolution = spec.get_float_attribute("XResolution", 0);
        out.y_resolution = spec.get_float_attribute("YResolution", 0);
        out.resolution_unit = spec.get_string_attribute("ResolutionUnit", "");
        return true;
    });
}

bool read_page(void* file, int page, Sample sample, void* out, std::string& error) {
    return guarded(error, [&] {
        auto& in = *static_cast<OIIO::ImageInput*>(file);
        // A page libtiff cannot decode may still "succeed" with its error only recorded.
        if (!in.read_image(page, 0, 0, 1, type_of(sample), out) || in.has_error())
            return error = in.geterror(), false;
        return true;
    });
}

constexpr Api kApi{kApiVersion, can_write,  encode_colour, encode_depth, read_colour, read_depth,
                   open_file,   close_file, page_count,    page_info,    read_page};

}  // namespace
}  // namespace isowall::oiio

extern "C" __attribute__((visibility("default"))) const isowall::oiio::Api* isowall_oiio_api() {
    return &isowall::oiio::kApi;
}
