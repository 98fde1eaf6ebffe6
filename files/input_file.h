#pragma once
// Small input files (wall files, scripts) are read whole, so what is read must be a regular file
// of bounded size: a folder would read as empty (a wall with "tiles: missing", an empty script),
// and /dev/zero or a pipe would never end.
#include <cstddef>
#include <filesystem>
#include <string>

namespace isowall {

// The bytes of `path`, or InputError(path, field, ...) when it does not exist, is a folder or
// anything but a regular file, cannot be read, or is larger than `max_bytes`.
std::string read_input_file(const std::filesystem::path& path, const std::string& field,
                            std::size_t max_bytes);

}  // namespace isowall
