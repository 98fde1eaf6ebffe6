#pragma once
// The mesh handed from the flying-edges side of the FE + Embree peer (scripts/fe_mesh.py, VTK in
// Python) to the ray side (isowall-peer, C++). A plain file in a temp folder, written and read
// outside every timed span.
//
// Layout, little-endian: the 8 bytes "ISOWMESH"; u32 version (1); u32 zero; f32 bounds min xyz
// and max xyz (the volume's, which set the view); u64 vertex count V; u64 triangle count T;
// f32 xyz[3V]; u32 indices[3T]. The file is exactly that long.
#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "core/box.h"

namespace isowall::peer {

inline constexpr std::array<char, 8> kMeshMagic{'I', 'S', 'O', 'W', 'M', 'E', 'S', 'H'};
inline constexpr std::uint32_t kMeshVersion = 1;
// Counts past this are refused before allocating (a 4x head has about 12 M triangles).
inline constexpr std::uint64_t kMaxMeshItems = std::uint64_t{1} << 31;

struct PeerMesh {
    Box3 bounds;                         // the volume's bounds, not the surface's
    std::vector<float> xyz;              // 3 per vertex
    std::vector<std::uint32_t> indices;  // 3 per triangle, counter-clockwise seen from outside
    std::size_t vertex_count() const { return xyz.size() / 3; }
    std::size_t triangle_count() const { return indices.size() / 3; }
};

// InputError naming the file and field on a short, long or inconsistent file.
PeerMesh read_peer_mesh(const std::filesystem::path& path);
void write_peer_mesh(const std::filesystem::path& path, const PeerMesh& mesh);

}  // namespace isowall::peer
