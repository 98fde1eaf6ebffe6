#pragma once
// A surface out in the formats other tools open, chosen by the file's extension:
//   .ply  binary PLY with vertex normals (ply.h), what isowall reads back;
//   .stl  binary STL: 80-byte header, a triangle count, then each triangle's facet normal and
//         three corners (3D printing and CAD take it; STL has no shared vertices or normals);
//   .obj  Wavefront OBJ text: v, vn, and f a//a b//b c//c (1-based) per triangle;
//   .vtp  VTK XML PolyData (ParaView, VTK): points, point normals ("Normals") and triangles as
//         polys, the arrays raw in an appended block with 64-bit sizes;
//   .glb  binary glTF 2.0 (the web's, Blender's): one mesh of one triangle primitive, POSITION
//         and NORMAL (float VEC3) and 32-bit indices in one buffer; with `meshopt`, the vertices
//         and triangles reordered for a GPU's caches and each view compressed by meshoptimizer
//         (EXT_meshopt_compression, required: three.js, Babylon.js and glTF-Transform decode it),
//         lossless, about a third of the plain file.
// Positions are object units (voxel index times spacing, as `info` prints the bounds); glTF,
// which states metres, gets the same numbers. Every writer stages its file and renames it into
// place (output_files.h): a failure leaves nothing behind.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh.h"

namespace isowall {

enum class MeshFormat { ply, stl, obj, vtp, glb };

// The format of `path` by its extension (any case), nullopt for another.
std::optional<MeshFormat> mesh_format_of(const std::filesystem::path& path);
// "PLY (.ply), STL (.stl), OBJ (.obj), VTK PolyData (.vtp) or glTF binary (.glb)": for messages.
std::string mesh_formats_named();

// Writes `mesh` in `format`; throws std::runtime_error naming `path` and the cause.
void write_mesh(const std::filesystem::path& path, const Mesh& mesh, MeshFormat format,
                bool meshopt = false);

// The bytes of each format (the writers' bodies, for tests that take them apart).
std::vector<std::byte> encode_stl(const Mesh& mesh);
std::vector<std::byte> encode_obj(const Mesh& mesh);
std::vector<std::byte> encode_vtp(const Mesh& mesh);
std::vector<std::byte> encode_glb(const Mesh& mesh);
std::vector<std::byte> encode_glb_meshopt(const Mesh& mesh);

}  // namespace isowall
