#include "common/io/image_io.h"

#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "common/core/error.h"
#include "common/core/output_files.h"

namespace isowall {
namespace {

[[noreturn]] void fail(std::string_view function, const std::filesystem::path& path,
                       std::string_view message) {
    throw std::runtime_error(std::string(function) + ": " + path.string() + ": " +
                             std::string(message));
}

void require_pixels(std::string_view function, const std::filesystem::path& path,
                    const Image& image, std::size_t values, std::size_t per_pixel) {
    if (image.width <= 0 || image.height <= 0 || values != image.pixel_count() * per_pixel) {
        fail(function, path,
             "image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                 " with " + std::to_string(values) + " values, expected " +
                 std::to_string(image.pixel_count() * per_pixel));
    }
}

// The writer for `path`'s format.
std::unique_ptr<OIIO::ImageOutput> create_output(std::string_view function,
                                                 const std::filesystem::path& path) {
    auto out = OIIO::ImageOutput::create(path.string());
    if (!out) fail(function, path, OIIO::geterror());
    return out;
}

// Writes `spec`-shaped pixels from `data` (with `xstride` bytes between pixels) to `temporary`,
// the staged file of `path` (its owner removes it on an error). A writer that takes an I/O proxy
// (PNG, among others) encodes into memory, and the bytes reach the file through one checked
// writer: OpenImageIO's PNG writer over stdio drops a full disk's error and closes "fine" on a
// cut-off file.
void write_pixels(std::string_view function, const std::filesystem::path& path,
                  const std::filesystem::path& temporary, const OIIO::ImageSpec& spec,
                  const void* data, OIIO::stride_t xstride) {
    auto out = create_output(function, path);
    const bool in_memory = out->supports("ioproxy");
    OIIO::Filesystem::IOVecOutput memory;
    OIIO::ImageSpec s = spec;
    if (in_memory) {
        OIIO::Filesystem::IOProxy* proxy = &memory;
        s.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
    }
    if (!out->open(temporary.string(), s)) fail(function, path, out->geterror());
    if (!out->write_image(spec.format, data, xstride)) fail(function, path, out->geterror());
    if (!out->close()) fail(function, path, out->geterror());
    if (in_memory)
        write_bytes_checked(temporary, {std::as_bytes(std::span(memory.buffer()))}, path.string());
}

void encode_image(const std::filesystem::path& path, const std::filesystem::path& temporary,
                  const Image& image) {
    require_pixels("write_image", path, image, image.rgba.size(), 4);
    const int channels = create_output("write_image", path)->supports("alpha") ? 4 : 3;
    OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::UINT8);
    if (channels == 4) {
        spec.alpha_channel = 3;
        // Our alpha is straight, not premultiplied; without this OIIO would divide colour by it.
        spec.attribute("oiio:UnassociatedAlpha", 1);
    }
    // With a 4-byte pixel stride, an RGB file simply skips each pixel's alpha.
    write_pixels("write_image", path, temporary, spec, image.rgba.data(), 4);
}

void encode_depth(const std::filesystem::path& path, const std::filesystem::path& temporary,
                  const Image& image) {
    require_pixels("write_depth", path, image, image.depth.size(), 1);
    OIIO::ImageSpec spec(image.width, image.height, 1, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"Z"};
    spec.z_channel = 0;
    write_pixels("write_depth", path, temporary, spec, image.depth.data(), sizeof(float));
}

}  // namespace

std::string image_format_problem(const std::filesystem::path& path) {
    if (OIIO::ImageOutput::create(path.string())) return {};
    OIIO::geterror();  // clear OIIO's pending message
    return "no image format for the extension " + quote(path.extension().string()) +
           " (e.g. .png, .tif, .exr)";
}

void write_image(const std::filesystem::path& path, const Image& image) {
    write_output(path, [&](const std::filesystem::path& t) { encode_image(path, t, image); });
}

void write_image(OutputFiles& batch, const std::filesystem::path& path, const Image& image) {
    encode_image(path, batch.stage(path), image);
}

void write_depth(const std::filesystem::path& path, const Image& image) {
    write_output(path, [&](const std::filesystem::path& t) { encode_depth(path, t, image); });
}

void write_depth(OutputFiles& batch, const std::filesystem::path& path, const Image& image) {
    encode_depth(path, batch.stage(path), image);
}

Image read_image(const std::filesystem::path& path) {
    OIIO::ImageSpec config;
    // Keep alpha straight so that write_image() followed by read_image() is exact.
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path.string(), &config);
    if (!in) fail("read_image", path, OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    const int channels = spec.nchannels;
    if (channels < 1 || channels > 4)
        fail("read_image", path, "expected 1 to 4 channels, found " + std::to_string(channels));
    std::vector<std::uint8_t> pixels(static_cast<std::size_t>(spec.width) * spec.height * channels);
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, pixels.data()))
        fail("read_image", path, in->geterror());

    Image image;
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
    return image;
}

Image read_depth(const std::filesystem::path& path) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) fail("read_depth", path, OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    Image image;
    image.resize(spec.width, spec.height);
    if (!in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, image.depth.data()))
        fail("read_depth", path, in->geterror());
    return image;
}

}  // namespace isowall
