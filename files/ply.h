#pragma once
// Binary little-endian PLY with per-vertex normals: what `isowall extract` writes.
#include <filesystem>

#include "core/mesh.h"
#include "files/output_files.h"

namespace isowall {

// Writes to a temporary file beside `path` and renames it, so a failure leaves nothing behind.
void write_ply(const std::filesystem::path& path, const Mesh& mesh);
// The same, staged in a command's batch: the file appears at batch.commit().
void write_ply(OutputFiles& batch, const std::filesystem::path& path, const Mesh& mesh);
// Reads back what write_ply writes (x y z nx ny nz floats, uchar-count int32 faces).
Mesh read_ply(const std::filesystem::path& path);

}  // namespace isowall
