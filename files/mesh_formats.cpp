#include "files/mesh_formats.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <span>
#include <string_view>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "files/output_files.h"
#include "files/ply.h"

namespace isowall {

static_assert(std::endian::native == std::endian::little,
              "the binary mesh formats are written from memory, little-endian");

namespace {

// Appends the bytes of trivially copyable values.
class Bytes {
  public:
    template <class T>
    void put(const T& v) {
        const auto* p = reinterpret_cast<const std::byte*>(&v);
        out_.insert(out_.end(), p, p + sizeof(T));
    }
    template <class T>
    void put_all(std::span<const T> values) {
        const auto bytes = std::as_bytes(values);
        out_.insert(out_.end(), bytes.begin(), bytes.end());
    }
    void put_text(std::string_view text) { put_all(std::span(text.data(), text.size())); }
    void pad_to_4(std::byte with) {
        while (out_.size() % 4) out_.push_back(with);
    }
    std::size_t size() const { return out_.size(); }
    std::vector<std::byte> take() { return std::move(out_); }

  private:
    std::vector<std::byte> out_;
};

glm::vec3 corner(const Mesh& m, std::size_t t, int k) {
    return m.positions[m.indices[3 * t + static_cast<std::size_t>(k)]];
}

// A unit normal for formats that require one: the vertex normal made unit, or +z where it has no
// direction (a vertex whose gradient vanished).
glm::vec3 unit_normal(glm::vec3 n) {
    const float len = glm::length(n);
    return len > 0 && std::isfinite(len) ? n / len : glm::vec3(0, 0, 1);
}

void append_number(std::string& s, float v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    s.append(buf, r.ptr);
}

std::vector<float> flat(const std::vector<glm::vec3>& v) {
    std::vector<float> out(3 * v.size());
    for (std::size_t i = 0; i < v.size(); ++i)
        for (int a = 0; a < 3; ++a) out[3 * i + static_cast<std::size_t>(a)] = v[i][a];
    return out;
}

std::vector<float> unit_normals(const Mesh& mesh) {
    std::vector<glm::vec3> n(mesh.normals.size());
    std::transform(mesh.normals.begin(), mesh.normals.end(), n.begin(), unit_normal);
    return flat(n);
}

}  // namespace

std::optional<MeshFormat> mesh_format_of(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".ply") return MeshFormat::ply;
    if (ext == ".stl") return MeshFormat::stl;
    if (ext == ".obj") return MeshFormat::obj;
    if (ext == ".vtp") return MeshFormat::vtp;
    if (ext == ".glb") return MeshFormat::glb;
    return std::nullopt;
}

std::string mesh_formats_named() {
    return "PLY (.ply), STL (.stl), OBJ (.obj), VTK PolyData (.vtp) or glTF binary (.glb)";
}

std::vector<std::byte> encode_stl(const Mesh& mesh) {
    Bytes b;
    char header[80] = {};
    std::snprintf(header, sizeof header, "isowall isosurface");  // never "solid": that is ASCII STL
    b.put(header);
    b.put(static_cast<std::uint32_t>(mesh.triangle_count()));
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const glm::vec3 p0 = corner(mesh, t, 0), p1 = corner(mesh, t, 1), p2 = corner(mesh, t, 2);
        const glm::vec3 c = glm::cross(p1 - p0, p2 - p0);
        const float len = glm::length(c);
        const glm::vec3 n = len > 0 ? c / len : glm::vec3(0);  // zero: readers compute it
        for (const glm::vec3& v : {n, p0, p1, p2}) b.put(v);
        b.put(std::uint16_t{0});
    }
    return b.take();
}

std::vector<std::byte> encode_obj(const Mesh& mesh) {
    std::string s = "# isowall isosurface: " + std::to_string(mesh.vertex_count()) + " vertices, " +
                    std::to_string(mesh.triangle_count()) + " triangles\n";
    s.reserve(s.size() + mesh.vertex_count() * 60 + mesh.triangle_count() * 30);
    auto vec = [&s](const char* tag, glm::vec3 v) {
        s += tag;
        for (int a = 0; a < 3; ++a) {
            s += ' ';
            append_number(s, v[a]);
        }
        s += '\n';
    };
    for (const glm::vec3& p : mesh.positions) vec("v", p);
    for (const glm::vec3& n : mesh.normals) vec("vn", n);
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        s += 'f';
        for (int k = 0; k < 3; ++k) {
            const std::string i = std::to_string(mesh.indices[3 * t + std::size_t(k)] + 1);
            s += ' ' + i + "//" + i;
        }
        s += '\n';
    }
    return {reinterpret_cast<const std::byte*>(s.data()),
            reinterpret_cast<const std::byte*>(s.data() + s.size())};
}

std::vector<std::byte> encode_vtp(const Mesh& mesh) {
    const std::vector<float> points = flat(mesh.positions), normals = flat(mesh.normals);
    std::vector<std::int64_t> connectivity(mesh.indices.begin(), mesh.indices.end());
    std::vector<std::int64_t> offsets(mesh.triangle_count());
    for (std::size_t t = 0; t < offsets.size(); ++t) offsets[t] = std::int64_t(3 * (t + 1));
    // The appended block: each array as its 64-bit byte count, then its bytes; an array's offset
    // counts from the block's first byte (after the '_').
    Bytes data;
    std::size_t at[4];
    auto array = [&data, &at](int i, auto values) {
        at[i] = data.size();
        data.put(static_cast<std::uint64_t>(values.size_bytes()));
        data.put_all(values);
    };
    array(0, std::span<const float>(points));
    array(1, std::span<const float>(normals));
    array(2, std::span<const std::int64_t>(connectivity));
    array(3, std::span<const std::int64_t>(offsets));
    const std::string xml =
        "<?xml version=\"1.0\"?>\n"
        "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
        "header_type=\"UInt64\">\n"
        " <PolyData>\n"
        "  <Piece NumberOfPoints=\"" +
        std::to_string(mesh.vertex_count()) +
        "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" +
        std::to_string(mesh.triangle_count()) +
        "\">\n"
        "   <PointData Normals=\"Normals\">\n"
        "    <DataArray type=\"Float32\" Name=\"Normals\" NumberOfComponents=\"3\" "
        "format=\"appended\" offset=\"" +
        std::to_string(at[1]) +
        "\"/>\n"
        "   </PointData>\n"
        "   <Points>\n"
        "    <DataArray type=\"Float32\" Name=\"Points\" NumberOfComponents=\"3\" "
        "format=\"appended\" offset=\"" +
        std::to_string(at[0]) +
        "\"/>\n"
        "   </Points>\n"
        "   <Polys>\n"
        "    <DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"" +
        std::to_string(at[2]) +
        "\"/>\n"
        "    <DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"" +
        std::to_string(at[3]) +
        "\"/>\n"
        "   </Polys>\n"
        "  </Piece>\n"
        " </PolyData>\n"
        " <AppendedData encoding=\"raw\">\n  _";
    Bytes out;
    out.put_text(xml);
    const std::vector<std::byte> block = data.take();
    out.put_all(std::span<const std::byte>(block));
    out.put_text("\n </AppendedData>\n</VTKFile>\n");
    return out.take();
}

namespace {

// glTF's numbers for what the file holds.
constexpr int kFloat = 5126, kUnsignedInt = 5125, kArrayBuffer = 34962, kElementArrayBuffer = 34963,
              kTriangles = 4;

// The document of one triangle mesh: POSITION, NORMAL and indices in bufferViews 0, 1 and 2.
nlohmann::json glb_document(const Mesh& mesh) {
    using nlohmann::json;
    json doc = {{"asset", {{"version", "2.0"}, {"generator", "isowall"}}},
                {"scene", 0},
                {"scenes", json::array({json::object()})}};
    if (mesh.empty()) return doc;
    const Box3 box = mesh.bounds();  // glTF asks for the positions' bounds
    const std::size_t n = mesh.vertex_count();
    doc["scenes"][0]["nodes"] = {0};
    doc["nodes"] = {{{"mesh", 0}, {"name", "isosurface"}}};
    doc["meshes"] = {{{"primitives",
                       {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}},
                         {"indices", 2},
                         {"mode", kTriangles}}}}}};
    doc["accessors"] = {
        {{"bufferView", 0},
         {"componentType", kFloat},
         {"count", n},
         {"type", "VEC3"},
         {"min", {box.min.x, box.min.y, box.min.z}},
         {"max", {box.max.x, box.max.y, box.max.z}}},
        {{"bufferView", 1}, {"componentType", kFloat}, {"count", n}, {"type", "VEC3"}},
        {{"bufferView", 2},
         {"componentType", kUnsignedInt},
         {"count", mesh.indices.size()},
         {"type", "SCALAR"}}};
    const std::size_t vec_bytes = 12 * n, index_bytes = 4 * mesh.indices.size();
    doc["bufferViews"] = {
        {{"buffer", 0}, {"byteOffset", 0}, {"byteLength", vec_bytes}, {"target", kArrayBuffer}},
        {{"buffer", 0},
         {"byteOffset", vec_bytes},
         {"byteLength", vec_bytes},
         {"target", kArrayBuffer}},
        {{"buffer", 0},
         {"byteOffset", 2 * vec_bytes},
         {"byteLength", index_bytes},
         {"target", kElementArrayBuffer}}};
    doc["buffers"] = {{{"byteLength", 2 * vec_bytes + index_bytes}}};
    return doc;
}

// The GLB container: a 12-byte header, the JSON chunk, the BIN chunk (where there is one).
std::vector<std::byte> glb_container(const nlohmann::json& doc, Bytes bin) {
    Bytes json_chunk;
    json_chunk.put_text(doc.dump());
    json_chunk.pad_to_4(std::byte{' '});
    bin.pad_to_4(std::byte{0});
    const std::vector<std::byte> j = json_chunk.take(), b = bin.take();
    Bytes out;
    out.put(std::uint32_t{0x46546C67});  // "glTF"
    out.put(std::uint32_t{2});
    out.put(static_cast<std::uint32_t>(12 + 8 + j.size() + (b.empty() ? 0 : 8 + b.size())));
    out.put(static_cast<std::uint32_t>(j.size()));
    out.put(std::uint32_t{0x4E4F534A});  // "JSON"
    out.put_all(std::span<const std::byte>(j));
    if (!b.empty()) {
        out.put(static_cast<std::uint32_t>(b.size()));
        out.put(std::uint32_t{0x004E4942});  // "BIN\0"
        out.put_all(std::span<const std::byte>(b));
    }
    return out.take();
}

}  // namespace

std::vector<std::byte> encode_glb(const Mesh& mesh) {
    Bytes bin;
    if (!mesh.empty()) {
        const std::vector<float> points = flat(mesh.positions), normals = unit_normals(mesh);
        bin.put_all(std::span<const float>(points));
        bin.put_all(std::span<const float>(normals));
        bin.put_all(std::span<const std::uint32_t>(mesh.indices));
    }
    return glb_container(glb_document(mesh), std::move(bin));
}

std::vector<std::byte> encode_glb_meshopt(const Mesh& mesh) {
    using nlohmann::json;
    json doc = glb_document(mesh);
    if (mesh.empty()) return glb_container(doc, Bytes());
    // The vertices in the order the triangles first use them, and the triangles in the order a
    // GPU's vertex cache likes: both codecs compress such a mesh best. The mesh is the same.
    const std::size_t n = mesh.vertex_count();
    std::vector<std::uint32_t> indices(mesh.indices.size());
    meshopt_optimizeVertexCache(indices.data(), mesh.indices.data(), indices.size(), n);
    std::vector<std::uint32_t> remap(n);
    const std::size_t used =
        meshopt_optimizeVertexFetchRemap(remap.data(), indices.data(), indices.size(), n);
    std::vector<float> points(3 * used), normals(3 * used);
    const std::vector<float> p = flat(mesh.positions), u = unit_normals(mesh);
    meshopt_remapVertexBuffer(points.data(), p.data(), n, 12, remap.data());
    meshopt_remapVertexBuffer(normals.data(), u.data(), n, 12, remap.data());
    meshopt_remapIndexBuffer(indices.data(), indices.data(), indices.size(), remap.data());
    // Each view's bytes encoded into the file's buffer (0); its plain bytes are those of a
    // fallback buffer (1) that the file leaves out, so a reader must know the extension.
    Bytes bin;
    auto encoded = [&bin](std::vector<unsigned char> bytes, std::size_t size) {
        const std::size_t offset = bin.size();
        bytes.resize(size);
        bin.put_all(std::span<const unsigned char>(bytes));
        bin.pad_to_4(std::byte{0});
        return std::pair{offset, size};
    };
    std::vector<std::pair<std::size_t, std::size_t>> views;
    for (const std::vector<float>* attribute : {&points, &normals}) {
        std::vector<unsigned char> out(meshopt_encodeVertexBufferBound(used, 12));
        views.push_back(encoded(
            out, meshopt_encodeVertexBuffer(out.data(), out.size(), attribute->data(), used, 12)));
    }
    std::vector<unsigned char> out(meshopt_encodeIndexBufferBound(indices.size(), used));
    views.push_back(encoded(
        out, meshopt_encodeIndexBuffer(out.data(), out.size(), indices.data(), indices.size())));
    const std::size_t counts[3] = {used, used, indices.size()}, strides[3] = {12, 12, 4};
    for (std::size_t i = 0; i < 3; ++i) {
        json& view = doc["bufferViews"][i];
        view["buffer"] = 1;
        if (i < 2) view["byteStride"] = 12;
        view["extensions"]["EXT_meshopt_compression"] = {
            {"buffer", 0},
            {"byteOffset", views[i].first},
            {"byteLength", views[i].second},
            {"byteStride", strides[i]},
            {"count", counts[i]},
            {"mode", i < 2 ? "ATTRIBUTES" : "TRIANGLES"}};
    }
    // The bounds of the vertices kept (glTF's min and max are the accessor's own).
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
    for (std::size_t v = 0; v < used; ++v) {
        const glm::vec3 q(points[3 * v], points[3 * v + 1], points[3 * v + 2]);
        lo = glm::min(lo, q), hi = glm::max(hi, q);
    }
    doc["accessors"][0]["min"] = {lo.x, lo.y, lo.z};
    doc["accessors"][0]["max"] = {hi.x, hi.y, hi.z};
    doc["accessors"][0]["count"] = used;
    doc["accessors"][1]["count"] = used;
    const std::size_t vec_bytes = 12 * used;
    doc["bufferViews"][1]["byteOffset"] = vec_bytes;
    doc["bufferViews"][0]["byteLength"] = doc["bufferViews"][1]["byteLength"] = vec_bytes;
    doc["bufferViews"][2]["byteOffset"] = 2 * vec_bytes;
    doc["buffers"] = {{{"byteLength", bin.size()}},
                      {{"byteLength", 2 * vec_bytes + 4 * indices.size()},
                       {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}};
    doc["extensionsUsed"] = doc["extensionsRequired"] = {"EXT_meshopt_compression"};
    return glb_container(doc, std::move(bin));
}

void write_mesh(const std::filesystem::path& path, const Mesh& mesh, MeshFormat format,
                bool meshopt) {
    if (format == MeshFormat::ply) return write_ply(path, mesh);
    write_output(path, [&](const std::filesystem::path& temporary) {
        const std::vector<std::byte> bytes = format == MeshFormat::stl   ? encode_stl(mesh)
                                             : format == MeshFormat::obj ? encode_obj(mesh)
                                             : format == MeshFormat::vtp ? encode_vtp(mesh)
                                             : meshopt                   ? encode_glb_meshopt(mesh)
                                                                         : encode_glb(mesh);
        write_bytes_checked(temporary, {std::span<const std::byte>(bytes)}, path.string());
    });
}

}  // namespace isowall
