// Meshes out (files/mesh_formats.h): each format's bytes taken apart field by field for a mesh of
// two triangles, an empty mesh in each, the format by extension, and the written files. The
// reference readers (VTK's, the Khronos glTF validator) read them in mesh_export_test.py.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "files/mesh_formats.h"

#include <meshoptimizer.h>

#include <array>
#include <set>
#include <tuple>

#include <glm/geometric.hpp>
#include "files/ply.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

// Two triangles over four vertices: a unit square in z = 2, seen from +z counter-clockwise, one
// normal not of unit length (the glTF writer makes it so).
Mesh square() {
    Mesh m;
    m.positions = {{0, 0, 2}, {1, 0, 2}, {1, 1, 2}, {0, 1, 2}};
    m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 2}, {0, 0, 1}};
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
}

template <class T>
T read_at(const std::vector<std::byte>& b, std::size_t at) {
    T v;
    std::memcpy(&v, b.data() + at, sizeof(T));
    return v;
}

std::string text(const std::vector<std::byte>& b) {
    return {reinterpret_cast<const char*>(b.data()), b.size()};
}

TEST(MeshFormats, KnowsTheirExtensionsInAnyCase) {
    EXPECT_EQ(mesh_format_of("a.ply"), MeshFormat::ply);
    EXPECT_EQ(mesh_format_of("dir.x/a.STL"), MeshFormat::stl);
    EXPECT_EQ(mesh_format_of("a.Obj"), MeshFormat::obj);
    EXPECT_EQ(mesh_format_of("a.vtp"), MeshFormat::vtp);
    EXPECT_EQ(mesh_format_of("a.glb"), MeshFormat::glb);
    EXPECT_EQ(mesh_format_of("a.gltf"), std::nullopt);  // text glTF with a side file: not written
    EXPECT_EQ(mesh_format_of("a"), std::nullopt);
    EXPECT_EQ(mesh_format_of("ply"), std::nullopt);
}

TEST(MeshFormats, StlHasACountThenNormalAndCornersPerTriangle) {
    const auto b = encode_stl(square());
    ASSERT_EQ(b.size(), 80u + 4 + 2 * 50);
    EXPECT_NE(text(b).substr(0, 5), "solid");  // a binary file that says "solid" reads as ASCII
    EXPECT_EQ(read_at<std::uint32_t>(b, 80), 2u);
    const std::size_t second = 84 + 50;
    EXPECT_EQ(read_at<float>(b, second + 8), 1.0f);            // facet normal z, from the corners
    EXPECT_EQ(read_at<float>(b, second + 12 + 12 + 0), 1.0f);  // corner 1 (1, 1, 2): x
    EXPECT_EQ(read_at<float>(b, second + 12 + 24 + 4), 1.0f);  // corner 2 (0, 1, 2): y
    EXPECT_EQ(read_at<float>(b, second + 12 + 24 + 8), 2.0f);
    EXPECT_EQ(read_at<std::uint16_t>(b, second + 48), 0u);
    EXPECT_EQ(encode_stl(Mesh{}).size(), 84u);
}

TEST(MeshFormats, ObjListsVerticesNormalsAndOneBasedFaces) {
    const std::string s = text(encode_obj(square()));
    EXPECT_NE(s.find("\nv 1 1 2\n"), std::string::npos) << s;
    EXPECT_NE(s.find("\nvn 0 0 2\n"), std::string::npos) << s;
    EXPECT_NE(s.find("\nf 1//1 3//3 4//4\n"), std::string::npos) << s;
    std::istringstream lines(s);
    int v = 0, vn = 0, f = 0;
    for (std::string line; std::getline(lines, line);) {
        v += line.rfind("v ", 0) == 0;
        vn += line.rfind("vn ", 0) == 0;
        f += line.rfind("f ", 0) == 0;
    }
    EXPECT_EQ((std::array{v, vn, f}), (std::array{4, 4, 2}));
    EXPECT_EQ(text(encode_obj(Mesh{})).find("\nv "), std::string::npos);
}

// The offset="N" of the DataArray named `name`.
std::size_t vtp_offset(const std::string& xml, const std::string& name) {
    const auto at = xml.find("Name=\"" + name + "\"");
    EXPECT_NE(at, std::string::npos) << name;
    const auto off = xml.find("offset=\"", at) + 8;
    return std::stoull(xml.substr(off));
}

TEST(MeshFormats, VtpArraysSitWhereTheirOffsetsSay) {
    const auto b = encode_vtp(square());
    const std::string xml = text(b);
    EXPECT_NE(xml.find("NumberOfPoints=\"4\""), std::string::npos);
    EXPECT_NE(xml.find("NumberOfPolys=\"2\""), std::string::npos);
    const std::size_t block = xml.find("encoding=\"raw\">") + std::strlen("encoding=\"raw\">");
    const std::size_t data = xml.find('_', block) + 1;
    const std::size_t points = data + vtp_offset(xml, "Points");
    EXPECT_EQ(read_at<std::uint64_t>(b, points), 4u * 12);
    EXPECT_EQ(read_at<float>(b, points + 8 + 2 * 12 + 4), 1.0f);  // point 2's y
    const std::size_t normals = data + vtp_offset(xml, "Normals");
    EXPECT_EQ(read_at<float>(b, normals + 8 + 2 * 12 + 8), 2.0f);  // written as given
    const std::size_t conn = data + vtp_offset(xml, "connectivity");
    EXPECT_EQ(read_at<std::uint64_t>(b, conn), 6u * 8);
    EXPECT_EQ(read_at<std::int64_t>(b, conn + 8 + 5 * 8), 3);
    const std::size_t offsets = data + vtp_offset(xml, "offsets");
    EXPECT_EQ(read_at<std::uint64_t>(b, offsets), 2u * 8);
    EXPECT_EQ(read_at<std::int64_t>(b, offsets + 8 + 8), 6);
    EXPECT_EQ(xml.substr(xml.size() - 11), "</VTKFile>\n");
    EXPECT_NE(text(encode_vtp(Mesh{})).find("NumberOfPolys=\"0\""), std::string::npos);
}

TEST(MeshFormats, GlbHasAHeaderAJsonChunkAndABinaryChunk) {
    const auto b = encode_glb(square());
    EXPECT_EQ(read_at<std::uint32_t>(b, 0), 0x46546C67u);
    EXPECT_EQ(read_at<std::uint32_t>(b, 4), 2u);
    EXPECT_EQ(read_at<std::uint32_t>(b, 8), b.size());
    const auto json_bytes = read_at<std::uint32_t>(b, 12);
    EXPECT_EQ(json_bytes % 4, 0u);
    EXPECT_EQ(read_at<std::uint32_t>(b, 16), 0x4E4F534Au);
    const auto doc = nlohmann::json::parse(text(b).substr(20, json_bytes));
    const auto& acc = doc["accessors"];
    EXPECT_EQ(acc[0]["count"], 4);
    EXPECT_EQ(acc[0]["min"], nlohmann::json({0.0, 0.0, 2.0}));
    EXPECT_EQ(acc[0]["max"], nlohmann::json({1.0, 1.0, 2.0}));
    EXPECT_EQ(acc[2]["count"], 6);
    const std::size_t bin = 20 + json_bytes;
    const auto bin_bytes = read_at<std::uint32_t>(b, bin);
    EXPECT_EQ(read_at<std::uint32_t>(b, bin + 4), 0x004E4942u);
    EXPECT_EQ(bin_bytes, doc["buffers"][0]["byteLength"].get<std::uint32_t>());
    EXPECT_EQ(bin + 8 + bin_bytes, b.size());
    const std::size_t normals = bin + 8 + doc["bufferViews"][1]["byteOffset"].get<std::size_t>();
    EXPECT_EQ(read_at<float>(b, normals + 2 * 12 + 8), 1.0f);  // made unit
    const std::size_t indices = bin + 8 + doc["bufferViews"][2]["byteOffset"].get<std::size_t>();
    EXPECT_EQ(read_at<std::uint32_t>(b, indices + 5 * 4), 3u);
    // An empty mesh: a scene with nothing in it, and no binary chunk.
    const auto e = encode_glb(Mesh{});
    EXPECT_EQ(read_at<std::uint32_t>(e, 8), e.size());
    EXPECT_EQ(e.size(), 20 + read_at<std::uint32_t>(e, 12));
    EXPECT_FALSE(nlohmann::json::parse(text(e).substr(20)).contains("meshes"));
}

// A glb's JSON chunk and BIN chunk.
std::pair<nlohmann::json, std::span<const std::byte>> glb_parts(const std::vector<std::byte>& b) {
    const auto json_bytes = read_at<std::uint32_t>(b, 12);
    const std::size_t bin = 20 + json_bytes;
    return {nlohmann::json::parse(text(b).substr(20, json_bytes)),
            std::span<const std::byte>(b).subspan(bin + 8, read_at<std::uint32_t>(b, bin))};
}

TEST(MeshFormats, MeshoptGlbDecodesToTheSameTriangles) {
    Mesh m = square();
    m.positions.push_back({9, 9, 9});  // a vertex no triangle uses: left out
    m.normals.push_back({0, 0, 1});
    const auto b = encode_glb_meshopt(m);
    EXPECT_EQ(read_at<std::uint32_t>(b, 8), b.size());
    const auto [doc, bin] = glb_parts(b);
    EXPECT_EQ(doc["extensionsRequired"], nlohmann::json({"EXT_meshopt_compression"}));
    EXPECT_TRUE(doc["buffers"][1]["extensions"]["EXT_meshopt_compression"]["fallback"]);
    EXPECT_EQ(doc["buffers"][0]["byteLength"].get<std::size_t>(), bin.size());
    EXPECT_EQ(doc["accessors"][0]["count"], 4);
    EXPECT_EQ(doc["accessors"][0]["max"], nlohmann::json({1.0, 1.0, 2.0}));  // not (9, 9, 9)
    // Each view decoded as a reader would, then the triangles' corners compared as sets.
    auto view = [&, &doc = doc, &bin = bin](int i) {
        const auto& e = doc["bufferViews"][i]["extensions"]["EXT_meshopt_compression"];
        return std::tuple{
            bin.subspan(e["byteOffset"].get<std::size_t>(), e["byteLength"].get<std::size_t>()),
            e["count"].get<std::size_t>(), e["byteStride"].get<std::size_t>(),
            e["mode"].get<std::string>()};
    };
    std::vector<glm::vec3> points(4), normals(4);
    std::vector<std::uint32_t> indices(6);
    for (int i = 0; i < 2; ++i) {
        const auto [data, count, stride, mode] = view(i);
        ASSERT_EQ(mode, "ATTRIBUTES");
        ASSERT_EQ(count * stride, 4u * 12);
        ASSERT_EQ(meshopt_decodeVertexBuffer(i == 0 ? points.data() : normals.data(), count, stride,
                                             reinterpret_cast<const unsigned char*>(data.data()),
                                             data.size()),
                  0);
    }
    const auto [data, count, stride, mode] = view(2);
    ASSERT_EQ(mode, "TRIANGLES");
    ASSERT_EQ(
        meshopt_decodeIndexBuffer(indices.data(), count, stride,
                                  reinterpret_cast<const unsigned char*>(data.data()), data.size()),
        0);
    auto corners = [](const std::vector<glm::vec3>& p, const std::vector<std::uint32_t>& ix) {
        std::multiset<std::array<float, 9>> tris;
        for (std::size_t t = 0; t < ix.size(); t += 3) {
            std::array<glm::vec3, 3> c = {p[ix[t]], p[ix[t + 1]], p[ix[t + 2]]};
            // The same triangle from any of its corners (the winding kept).
            std::rotate(c.begin(),
                        std::min_element(c.begin(), c.end(),
                                         [](auto a, auto b) {
                                             return std::tie(a.x, a.y, a.z) <
                                                    std::tie(b.x, b.y, b.z);
                                         }),
                        c.end());
            tris.insert({c[0].x, c[0].y, c[0].z, c[1].x, c[1].y, c[1].z, c[2].x, c[2].y, c[2].z});
        }
        return tris;
    };
    EXPECT_EQ(corners(points, indices), corners(m.positions, m.indices));
    for (const glm::vec3& n : normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-6f);
}

TEST(MeshFormats, WritesEachFormatWhole) {
    const auto dir = test::scratch_dir("mesh_formats");
    for (const auto& [name, format] :
         {std::pair{"a.ply", MeshFormat::ply}, std::pair{"a.stl", MeshFormat::stl},
          std::pair{"a.obj", MeshFormat::obj}, std::pair{"a.vtp", MeshFormat::vtp},
          std::pair{"a.glb", MeshFormat::glb}}) {
        write_mesh(dir / name, square(), format);
        EXPECT_GT(std::filesystem::file_size(dir / name), 0u) << name;
    }
    EXPECT_EQ(read_ply(dir / "a.ply").triangle_count(), 2u);
    std::ifstream glb(dir / "a.glb", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(glb)), {});
    const auto encoded = encode_glb(square());
    EXPECT_EQ(bytes, text(encoded));
    // Into a folder that is not there: an error naming the file, and nothing written.
    EXPECT_THROW(write_mesh(dir / "no" / "a.stl", square(), MeshFormat::stl), std::runtime_error);
    EXPECT_FALSE(std::filesystem::exists(dir / "no"));
}

}  // namespace
}  // namespace isowall
