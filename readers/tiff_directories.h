#pragma once
// A walk over a TIFF file's chain of image file directories (one per page) that checks each lies
// whole within the file, before OpenImageIO counts the pages: libtiff stops at a directory it
// cannot read as if the file had ended there, so a multi-page TIFF cut inside its last directory
// read as one slice fewer, silently. The walk reads the header, each directory's entry count and
// its link to the next; entries are skipped. Classic TIFF and BigTIFF, either byte order.
#include <cstdint>
#include <istream>
#include <string>

namespace isowall::formats {

struct TiffDirectories {
    int pages = 0;        // directories found whole, in the chain's order
    std::string problem;  // empty, or why the chain is damaged (its page named)
};

// The directories of the `size`-byte TIFF file `in`. A chain that loops, or that passes
// kMaxTiffPages, is a problem too (a loop would otherwise never end).
inline constexpr int kMaxTiffPages = 1 << 20;
TiffDirectories tiff_directories(std::istream& in, std::uint64_t size);

}  // namespace isowall::formats
