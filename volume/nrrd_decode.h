#pragma once
// The data part of a NRRD file, decoded by us rather than by Teem: Teem's readers trust the
// header (an ascii token longer than its buffer smashed the stack, compressed data longer than
// the header says was accepted, a line skip on a device read forever). Each decoder takes the
// bytes after the header and skips, checks the count exactly (shorter or longer is an error),
// grows its output only as data arrives (a header claiming terabytes allocates nothing up front)
// and reports every failure as an InputError naming `where` (the data file) and the field.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "volume/volume.h"

namespace isowall {

// The offset just past `lines` more newlines from `offset`; an error when the bytes end first.
std::size_t skip_lines(std::span<const std::byte> bytes, std::size_t offset, std::uint64_t lines,
                       const std::string& where);

// gzip (or zlib) streams, one or more members back to back, that inflate to exactly `need` bytes.
std::vector<std::byte> decode_gzip(std::span<const std::byte> in, std::uint64_t need,
                                   const std::string& where);
// bzip2 streams that decompress to exactly `need` bytes.
std::vector<std::byte> decode_bzip2(std::span<const std::byte> in, std::uint64_t need,
                                    const std::string& where);
// Exactly `count` numbers of `type` as text, separated by whitespace or commas; integers must be
// whole numbers in the type's range, floats may be nan or inf. A value longer than 64 characters
// is an error, so nothing is read into a fixed buffer unchecked.
std::vector<std::byte> decode_ascii(std::span<const std::byte> in, VoxelType type,
                                    std::uint64_t count, const std::string& where);
// Exactly `need` bytes as pairs of hex digits, whitespace between pairs ignored.
std::vector<std::byte> decode_hex(std::span<const std::byte> in, std::uint64_t need,
                                  const std::string& where);

}  // namespace isowall
