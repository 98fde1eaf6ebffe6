#include "common/io/image_io.h"

#include <unistd.h>

#include <atomic>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include <OpenImageIO/imageio.h>

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

// Beside the target, so the final rename stays on one file system and is atomic; hidden, and
// unique per process and call, so concurrent writers never share one. The extension is kept
// because OIIO picks the format by it.
std::filesystem::path temporary_path(const std::filesystem::path& path) {
    static std::atomic<unsigned> counter{0};
    // Appended piece by piece: GCC 12 misreports "." + std::string as an overlapping memcpy.
    std::string name(".");
    name += path.stem().string();
    name += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    name += path.extension().string();
    return path.parent_path() / name;
}

// The writer for `path`'s format.
std::unique_ptr<OIIO::ImageOutput> create_output(std::string_view function,
                                                 const std::filesystem::path& path) {
    auto out = OIIO::ImageOutput::create(path.string());
    if (!out) fail(function, path, OIIO::geterror());
    return out;
}

// Writes `spec`-shaped pixels from `data` (with `xstride` bytes between pixels) to a temporary
// file, then renames it to `path`.
void write_atomically(std::string_view function, const std::filesystem::path& path,
                      OIIO::ImageOutput& out, const OIIO::ImageSpec& spec, const void* data,
                      OIIO::stride_t xstride) {
    const std::filesystem::path temporary = temporary_path(path);
    const auto discard = [&](const std::string& message) {
        std::error_code ignored;
        std::filesystem::remove(temporary, ignored);
        fail(function, path, message);
    };
    if (!out.open(temporary.string(), spec)) discard(out.geterror());
    if (!out.write_image(spec.format, data, xstride)) discard(out.geterror());
    if (!out.close()) discard(out.geterror());
    std::error_code error;
    std::filesystem::rename(temporary, path, error);
    if (error) discard("rename from " + temporary.string() + ": " + error.message());
}

}  // namespace

void write_image(const std::filesystem::path& path, const Image& image) {
    require_pixels("write_image", path, image, image.rgba.size(), 4);
    auto out = create_output("write_image", path);
    const int channels = out->supports("alpha") ? 4 : 3;
    OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::UINT8);
    if (channels == 4) {
        spec.alpha_channel = 3;
        // Our alpha is straight, not premultiplied; without this OIIO would divide colour by it.
        spec.attribute("oiio:UnassociatedAlpha", 1);
    }
    // With a 4-byte pixel stride, an RGB file simply skips each pixel's alpha.
    write_atomically("write_image", path, *out, spec, image.rgba.data(), 4);
}

void write_depth(const std::filesystem::path& path, const Image& image) {
    require_pixels("write_depth", path, image, image.depth.size(), 1);
    OIIO::ImageSpec spec(image.width, image.height, 1, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"Z"};
    spec.z_channel = 0;
    auto out = create_output("write_depth", path);
    write_atomically("write_depth", path, *out, spec, image.depth.data(), sizeof(float));
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
