#include "files/ply.h"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "files/output_files.h"

namespace isowall {

namespace {

// The file at `temporary` (staged for `path`, which errors name).
void encode_ply(const std::filesystem::path& path, const std::filesystem::path& temporary,
                const Mesh& mesh) {
    std::ostringstream out;
    out << "ply\nformat binary_little_endian 1.0\ncomment isowall isosurface\n"
        << "element vertex " << mesh.positions.size() << "\n"
        << "property float x\nproperty float y\nproperty float z\n"
        << "property float nx\nproperty float ny\nproperty float nz\n"
        << "element face " << mesh.triangle_count() << "\n"
        << "property list uchar int vertex_indices\nend_header\n";
    std::vector<float> verts(mesh.positions.size() * 6);
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        for (int a = 0; a < 3; ++a) {
            verts[6 * i + a] = mesh.positions[i][a];
            verts[6 * i + 3 + a] = mesh.normals[i][a];
        }
    }
    const std::string header = out.str();
    // 13 bytes per face: the count byte and three int32 indices, packed.
    std::vector<char> faces(mesh.triangle_count() * 13);
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        char* f = faces.data() + 13 * t;
        f[0] = 3;
        for (int k = 0; k < 3; ++k) {
            const auto idx =
                static_cast<std::int32_t>(mesh.indices[3 * t + static_cast<std::size_t>(k)]);
            std::memcpy(f + 1 + 4 * k, &idx, 4);
        }
    }
    // Through the one checked writer: a full disk is an error naming the file and the cause.
    write_bytes_checked(temporary,
                        {std::as_bytes(std::span(header)), std::as_bytes(std::span(verts)),
                         std::as_bytes(std::span(faces))},
                        path.string());
}

}  // namespace

void write_ply(const std::filesystem::path& path, const Mesh& mesh) {
    write_output(path, [&](const std::filesystem::path& t) { encode_ply(path, t, mesh); });
}

void write_ply(OutputFiles& batch, const std::filesystem::path& path, const Mesh& mesh) {
    encode_ply(path, batch.stage(path), mesh);
}

Mesh read_ply(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path.string() + ": cannot open");
    std::size_t nv = 0, nf = 0;
    for (std::string line; std::getline(in, line) && line != "end_header";) {
        std::istringstream ls(line);
        std::string word, kind;
        ls >> word;
        if (word == "element") {
            ls >> kind;
            (kind == "vertex" ? nv : nf) = 0;
            ls >> (kind == "vertex" ? nv : nf);
        }
    }
    Mesh m;
    std::vector<float> verts(nv * 6);
    in.read(reinterpret_cast<char*>(verts.data()),
            static_cast<std::streamsize>(verts.size() * sizeof(float)));
    m.positions.resize(nv);
    m.normals.resize(nv);
    for (std::size_t i = 0; i < nv; ++i)
        for (int a = 0; a < 3; ++a) {
            m.positions[i][a] = verts[6 * i + a];
            m.normals[i][a] = verts[6 * i + 3 + a];
        }
    m.indices.resize(nf * 3);
    for (std::size_t t = 0; t < nf; ++t) {
        char f[13];
        in.read(f, 13);
        for (int k = 0; k < 3; ++k) {
            std::int32_t idx;
            std::memcpy(&idx, f + 1 + 4 * k, 4);
            m.indices[3 * t + static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(idx);
        }
    }
    if (!in) throw std::runtime_error(path.string() + ": truncated PLY");
    return m;
}

}  // namespace isowall
