// Writes groups in the `cells` encoding with the mesh the C++ decoder (decode_group) gives for
// each, for the page's tests and bench (web/test/cells.test.mjs, web/tools/bench_decode.mjs): the
// page's WebAssembly decoder must give the same mesh to the bit. Each group goes in compact+zstd
// too (the encoding the adaptive server weighs cells against).
//   cells_probe reference OUT CORPUS [CTHEAD.nhdr]
//       small groups: the cells groups of CORPUS (fuzz/corpus/group_codec), passes of the phantom
//       in all eight voxel types (level 0, meta-cells of level 2 whose normals come from their
//       faces and integer values go to a step, a refinement), and of the CT head when given
//       (committed: cells_groups.bin)
//   cells_probe frame OUT [VOLUME ISO]
//       one frame's groups, as isowall_bench_codec makes them (the phantom at iso 50 by default);
//       prints the C++ decoder's triangles a second on them
// Build (web/README.md has the line): against build/'s static libraries.
//
// OUT: u32 group count, then per group (little endian)
//   name: u32 length, bytes; cells: u32 length, the encoded group (its encoding byte says whether
//   it went as cells: a coarse pass may not, see group_codec.h); compact+zstd: u32 length, bytes;
//   exact: u32 length, the bits of its ExactMsg (empty unless its gradients went to a step: the
//   "-stepped" groups, as the server sends them to a client that takes exact values); the decoded
//   mesh (with the exact bits): u32 vertex count V, u32 index count I, V x 3 f32 positions, V x 3
//   f32 normals, I x u32 indices.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <span>
#include <string>
#include <vector>

#include "remote/group_codec.h"
#include "remote/sample_groups.h"
#include "volume/phantom.h"

namespace {

using namespace isowall;
using namespace isowall::remote;
using Clock = std::chrono::steady_clock;

struct Entry {
    std::string name;
    std::vector<std::uint8_t> cells, compact;
    std::vector<std::uint8_t> exact;  // its gradients' exact values (ExactMsg), if stepped
    Mesh mesh;                        // decode_group(cells), with `exact`
};

class Out {
  public:
    void u32(std::size_t v) {
        const auto x = static_cast<std::uint32_t>(v);
        raw(&x, sizeof x);
    }
    void bytes(std::span<const std::uint8_t> b) {
        u32(b.size());
        raw(b.data(), b.size());
    }
    void raw(const void* p, std::size_t n) {
        const auto* c = static_cast<const std::uint8_t*>(p);
        data_.insert(data_.end(), c, c + n);
    }
    const std::vector<std::uint8_t>& data() const { return data_; }

  private:
    std::vector<std::uint8_t> data_;
};

std::vector<std::uint8_t> read_file(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read " + p.string());
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write(const std::filesystem::path& path, const std::vector<Entry>& entries) {
    Out o;
    o.u32(entries.size());
    for (const Entry& e : entries) {
        o.bytes(std::span(reinterpret_cast<const std::uint8_t*>(e.name.data()), e.name.size()));
        o.bytes(e.cells);
        o.bytes(e.compact);
        o.bytes(e.exact);
        o.u32(e.mesh.vertex_count());
        o.u32(e.mesh.indices.size());
        o.raw(e.mesh.positions.data(), e.mesh.positions.size() * sizeof(glm::vec3));
        o.raw(e.mesh.normals.data(), e.mesh.normals.size() * sizeof(glm::vec3));
        o.raw(e.mesh.indices.data(), e.mesh.indices.size() * sizeof(std::uint32_t));
    }
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(o.data().data()),
              static_cast<std::streamsize>(o.data().size()));
    if (!out) throw std::runtime_error("cannot write " + path.string());
}

// What the server sends (server_session.cpp): compact positions on the volume's grid.
float grid_step(const Volume& v) {
    const Box3 b = v.bounds();
    const glm::vec3 far = glm::max(glm::abs(b.min), glm::abs(b.max));
    return position_grid_step(2 * std::max({far.x, far.y, far.z}));
}

// With `stepped`, the group as the server sends it to a client that takes exact values.
Entry entry(std::string name, const Group& g, const Volume& v, bool stepped = false) {
    Entry e{
        std::move(name), {}, encode_group(g, GroupEncoding::compact_zstd, grid_step(v)), {}, {}};
    e.cells = encode_group(g, GroupEncoding::cells, grid_step(v), &v, stepped ? &e.exact : nullptr);
    const std::span<const std::uint8_t> bits(e.exact);
    e.mesh = decode_group(e.cells, {e.exact.empty() ? nullptr : &bits, nullptr}).mesh;
    return e;
}

// The phantom's voxels as type T: v * scale + offset (non-integer for the floating types, so
// crossings fall between samples in ways a u8 volume never makes).
template <class T>
Volume convert(const Volume& u8, double scale, double offset, VoxelType type) {
    const auto src = u8.view<std::uint8_t>();
    std::vector<std::byte> bytes(u8.voxel_count() * sizeof(T));
    T* dst = reinterpret_cast<T*>(bytes.data());
    for (std::size_t i = 0; i < u8.voxel_count(); ++i)
        dst[i] = static_cast<T>(src.data[i] * scale + offset);
    return Volume(u8.dims(), type, u8.spacing(), std::move(bytes), "phantom converted");
}

// A few small passes of `v` at `iso`: level 0, meta-cells of level 2 and a refinement of one.
void passes(std::vector<Entry>& out, const std::string& name, const Volume& v, double iso,
            int max_count, bool coarse) {
    const auto fine = sample_groups(v, iso, 5, max_count);
    out.push_back(entry(name + "-cells", fine.at(0), v));
    // Integer voxels whose crossed edges span values enough: the gradients go to a step.
    if (Entry s = entry(name + "-stepped", fine.at(0), v, true); !s.exact.empty())
        out.push_back(std::move(s));
    if (!coarse) return;
    const auto meta = sample_groups(v, iso, 5, max_count / 4, uniform_levels(2));
    out.push_back(entry(name + "-level2", meta.at(0), v));
    auto ex = make_surface_extractor(v);
    ex->begin_frame(iso, uniform_levels(2));
    out.push_back(entry(name + "-refinement", ex->refine(meta.at(0).cells.at(0), 2, 3, {}), v));
}

int reference(const std::filesystem::path& out, const std::filesystem::path& corpus,
              const char* cthead) {
    std::vector<Entry> entries;
    // The seed corpus's cells groups, decoded as they are.
    for (const char* seed :
         {"cells-phantom-cells", "cells-phantom-level2", "cells-phantom-refinement"}) {
        Entry e{std::string("corpus-") + seed, read_file(corpus / seed), {}, {}, {}};
        const Group g = decode_group(e.cells);
        e.compact = encode_group(g, GroupEncoding::compact_zstd);
        e.mesh = g.mesh;
        entries.push_back(std::move(e));
    }
    PhantomSpec spec;
    spec.dims = {60, 56, 52};
    const Volume u8 = make_phantom(spec);
    const double skin = kPhantomSkinIso;
    passes(entries, "u8", u8, skin, 120, true);
    passes(entries, "i8", convert<std::int8_t>(u8, 0.5, -64, VoxelType::i8), skin * 0.5 - 64, 120,
           false);
    passes(entries, "u16", convert<std::uint16_t>(u8, 97, 3, VoxelType::u16), skin * 97 + 3.5, 120,
           true);
    passes(entries, "i16", convert<std::int16_t>(u8, 61, -9000, VoxelType::i16), skin * 61 - 9000,
           120, false);
    passes(entries, "u32", convert<std::uint32_t>(u8, 1e6, 7, VoxelType::u32), skin * 1e6, 120,
           false);
    passes(entries, "i32", convert<std::int32_t>(u8, -3e5, 5, VoxelType::i32), skin * -3e5 + 5, 120,
           false);
    passes(entries, "f32", convert<float>(u8, 0.013, -0.7, VoxelType::f32), skin * 0.013 - 0.7, 120,
           true);
    passes(entries, "f64", convert<double>(u8, -1.7e-3, 1e3, VoxelType::f64), skin * -1.7e-3 + 1e3,
           120, false);
    spec.spacing = {0.7f, 1.3f, 2.1f};
    passes(entries, "u8-spacing", make_phantom(spec), skin, 120, true);
    if (cthead) passes(entries, "cthead", load_volume(cthead, std::nullopt), 600, 200, true);
    write(out, entries);
    for (const Entry& e : entries)
        std::printf("%-24s %s, %zu triangles, %zu bytes (compact+zstd %zu)\n", e.name.c_str(),
                    to_string(encoding_of(e.cells)), e.mesh.triangle_count(), e.cells.size(),
                    e.compact.size());
    std::printf("cells_probe: %zu groups in %s\n", entries.size(), out.c_str());
    return 0;
}

// Best of five, in seconds, of decoding every group's bytes in `which`.
template <class F>
double best_s(const std::vector<Entry>& entries, F which) {
    double best = 1e300;
    for (int run = 0; run < 5; ++run) {
        const auto t0 = Clock::now();
        std::size_t kept = 0;
        for (const Entry& e : entries) kept += decode_group(which(e)).mesh.indices.size();
        best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
        if (kept == 0) std::printf(" ");
    }
    return best;
}

int frame(const std::filesystem::path& out, int argc, char** argv) {
    const bool phantom = argc < 5;
    const Volume v = phantom ? make_phantom() : load_volume(argv[3], std::nullopt);
    const double iso = phantom ? kPhantomSkinIso : std::stod(argv[4]);
    std::vector<Entry> entries;
    std::size_t triangles = 0, cells_bytes = 0, compact_bytes = 0, fell_back = 0;
    for (const Group& g : sample_groups(v, iso, 600, 2000)) {
        entries.push_back(entry("group " + std::to_string(g.id), g, v));
        triangles += g.mesh.triangle_count();
        cells_bytes += entries.back().cells.size();
        compact_bytes += entries.back().compact.size();
        if (encoding_of(entries.back().cells) != GroupEncoding::cells) ++fell_back;
    }
    write(out, entries);
    const double cells_s = best_s(entries, [](const Entry& e) { return e.cells; });
    const double compact_s = best_s(entries, [](const Entry& e) { return e.compact; });
    std::printf("cells_probe: %s at iso %g: %zu groups (%zu not as cells), %zu triangles in %s\n",
                phantom ? "phantom" : argv[3], iso, entries.size(), fell_back, triangles,
                out.c_str());
    const double t = static_cast<double>(triangles);
    std::printf(
        "C++ decode_group, best of 5: cells %.2f Mtri/s (%zu bytes), compact+zstd %.2f "
        "Mtri/s (%zu bytes)\n",
        t / cells_s / 1e6, cells_bytes, t / compact_s / 1e6, compact_bytes);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const std::string mode = argc >= 3 ? argv[1] : "";
        if (mode == "reference" && (argc == 4 || argc == 5))
            return reference(argv[2], argv[3], argc == 5 ? argv[4] : nullptr);
        if (mode == "frame" && (argc == 3 || argc == 5)) return frame(argv[2], argc, argv);
        std::fprintf(stderr,
                     "usage: cells_probe reference OUT CORPUS [CTHEAD.nhdr] | frame OUT [VOLUME "
                     "ISO]\n");
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "cells_probe: error: %s\n", e.what());
        return 1;
    }
}
