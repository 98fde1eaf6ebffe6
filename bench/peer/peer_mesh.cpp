#include "bench/peer/peer_mesh.h"

#include <bit>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>

#include "core/error.h"

namespace isowall::peer {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the mesh file is read and written as the machine's bytes, little-endian");

constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 6 * 4 + 8 + 8;

template <class T>
T take(const char*& p) {
    T v;
    std::memcpy(&v, p, sizeof v);
    p += sizeof v;
    return v;
}

}  // namespace

PeerMesh read_peer_mesh(const std::filesystem::path& path) {
    const std::string where = path.string();
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(where, "file", "cannot open");
    char head[kHeaderBytes];
    if (!in.read(head, sizeof head))
        throw InputError(where, "header",
                         "shorter than its " + std::to_string(kHeaderBytes) + " bytes");
    if (std::memcmp(head, kMeshMagic.data(), kMeshMagic.size()) != 0)
        throw InputError(where, "magic", "expected ISOWMESH");
    const char* p = head + kMeshMagic.size();
    if (const auto version = take<std::uint32_t>(p); version != kMeshVersion)
        throw InputError(where, "version", "expected 1, got " + std::to_string(version));
    take<std::uint32_t>(p);
    PeerMesh mesh;
    for (int i = 0; i < 3; ++i) mesh.bounds.min[i] = take<float>(p);
    for (int i = 0; i < 3; ++i) mesh.bounds.max[i] = take<float>(p);
    const auto vertices = take<std::uint64_t>(p);
    const auto triangles = take<std::uint64_t>(p);
    if (vertices > kMaxMeshItems || triangles > kMaxMeshItems)
        throw InputError(where, "counts", "over 2^31 vertices or triangles");
    const std::uint64_t expected = kHeaderBytes + 12 * vertices + 12 * triangles;
    if (std::filesystem::file_size(path) != expected)
        throw InputError(where, "size",
                         "expected " + std::to_string(expected) + " bytes for " +
                             std::to_string(vertices) + " vertices and " +
                             std::to_string(triangles) + " triangles");
    mesh.xyz.resize(3 * vertices);
    mesh.indices.resize(3 * triangles);
    in.read(reinterpret_cast<char*>(mesh.xyz.data()), std::streamsize(12 * vertices));
    in.read(reinterpret_cast<char*>(mesh.indices.data()), std::streamsize(12 * triangles));
    if (!in) throw InputError(where, "data", "cannot read");
    for (std::uint32_t i : mesh.indices)
        if (i >= vertices)
            throw InputError(
                where, "indices",
                "index " + std::to_string(i) + " past " + std::to_string(vertices) + " vertices");
    return mesh;
}

void write_peer_mesh(const std::filesystem::path& path, const PeerMesh& mesh) {
    std::ofstream out(path, std::ios::binary);
    const std::uint32_t version = kMeshVersion, zero = 0;
    const std::uint64_t vertices = mesh.vertex_count(), triangles = mesh.triangle_count();
    out.write(kMeshMagic.data(), kMeshMagic.size());
    out.write(reinterpret_cast<const char*>(&version), 4);
    out.write(reinterpret_cast<const char*>(&zero), 4);
    out.write(reinterpret_cast<const char*>(&mesh.bounds.min), 12);
    out.write(reinterpret_cast<const char*>(&mesh.bounds.max), 12);
    out.write(reinterpret_cast<const char*>(&vertices), 8);
    out.write(reinterpret_cast<const char*>(&triangles), 8);
    out.write(reinterpret_cast<const char*>(mesh.xyz.data()), std::streamsize(12 * vertices));
    out.write(reinterpret_cast<const char*>(mesh.indices.data()), std::streamsize(12 * triangles));
    if (!out) throw std::runtime_error(path.string() + ": cannot write the mesh");
}

}  // namespace isowall::peer
