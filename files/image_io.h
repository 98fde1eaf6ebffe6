#pragma once
// Reading and writing frames with OpenImageIO, loaded on first use (files/oiio_module.h).
// Writers go through a temporary file in the target folder and rename it into place
// (files/output_files.h), so a failed or interrupted write never leaves a half-written image
// behind; the OutputFiles forms stage the file in a command's batch, to appear with its other
// outputs at commit. Every error is a std::runtime_error naming the file and OIIO's message.
#include <filesystem>
#include <string>
#include <vector>

#include "core/image.h"
#include "files/output_files.h"

namespace isowall {

// Colour, format by extension (PNG, TIFF, ...): RGBA where the format stores alpha, else RGB.
void write_image(const std::filesystem::path& path, const Image& image);
void write_image(OutputFiles& batch, const std::filesystem::path& path, const Image& image);
// Window depth as one float channel "Z"; use an .exr path.
void write_depth(const std::filesystem::path& path, const Image& image);
void write_depth(OutputFiles& batch, const std::filesystem::path& path, const Image& image);

// Why no image can be written to `path` by its extension (OpenImageIO has no writer for it), or
// empty: checked with the output paths, before any work. The common extensions below are known
// without loading OpenImageIO (a test checks that it writes each); any other asks it.
std::string image_format_problem(const std::filesystem::path& path);
const std::vector<std::string>& common_image_extensions();

// Loads OpenImageIO on a thread of its own, so that the first image written or read later does
// not wait for it: a command that will write an image calls it once its timed work is done.
void preload_image_io();

// Colour of an 8-bit image (grey, grey+alpha, RGB or RGBA; missing alpha reads as opaque). Files
// hold no depth, so depth is 1 (nothing drawn) everywhere.
Image read_image(const std::filesystem::path& path);
// The first channel of a depth file written by write_depth(); rgba is black.
Image read_depth(const std::filesystem::path& path);

}  // namespace isowall
