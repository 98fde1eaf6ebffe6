#include "files/image_io.h"

#include <algorithm>
#include <cctype>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "files/oiio_module.h"
#include "files/output_files.h"

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

using Encode = bool (*)(const std::string&, const std::string&, const Image&,
                        std::vector<unsigned char>&, std::string&);

// Encodes through the module (files/oiio_module.h) into `temporary`, the staged file of `path`
// (its owner removes it on an error); bytes encoded in memory reach the file through one checked
// writer.
void encode_file(std::string_view function, const std::filesystem::path& path,
                 const std::filesystem::path& temporary, const Image& image, Encode encode) {
    std::vector<unsigned char> memory;
    std::string error;
    if (!encode(path.string(), temporary.string(), image, memory, error))
        fail(function, path, error);
    if (!memory.empty())
        write_bytes_checked(temporary, {std::as_bytes(std::span(memory))}, path.string());
}

void encode_image(const std::filesystem::path& path, const std::filesystem::path& temporary,
                  const Image& image) {
    require_pixels("write_image", path, image, image.rgba.size(), 4);
    encode_file("write_image", path, temporary, image, oiio::api().encode_colour);
}

void encode_depth(const std::filesystem::path& path, const std::filesystem::path& temporary,
                  const Image& image) {
    require_pixels("write_depth", path, image, image.depth.size(), 1);
    encode_file("write_depth", path, temporary, image, oiio::api().encode_depth);
}

}  // namespace

const std::vector<std::string>& common_image_extensions() {
    static const std::vector<std::string> list{".png",  ".tif", ".tiff", ".exr", ".jpg",
                                               ".jpeg", ".bmp", ".tga",  ".hdr", ".ppm"};
    return list;
}

std::string image_format_problem(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const auto& common = common_image_extensions();
    if (std::find(common.begin(), common.end(), ext) != common.end()) return {};
    if (oiio::api().can_write(path.string())) return {};
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

void preload_image_io() {
    std::thread([] {
        try {
            oiio::api();
        } catch (...) {
            // The first image written says why the module cannot be loaded.
        }
    }).detach();
}

Image read_image(const std::filesystem::path& path) {
    Image image;
    std::string error;
    if (!oiio::api().read_colour(path.string(), image, error)) fail("read_image", path, error);
    return image;
}

Image read_depth(const std::filesystem::path& path) {
    Image image;
    std::string error;
    if (!oiio::api().read_depth(path.string(), image, error)) fail("read_depth", path, error);
    return image;
}

}  // namespace isowall
