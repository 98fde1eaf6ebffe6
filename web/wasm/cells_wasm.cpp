// The page's decoder of `cells` group bodies (remote/cell_codec.h), compiled to WebAssembly by
// web/wasm/build.sh: the server's own decoder, so the page runs the project's marching cubes and
// gets the server's triangles to the bit. A small C API over one decoded mesh at a time (the page
// decodes groups one after another on its one thread): decode, then read the arrays through the
// accessors, which stay valid until the next decode.
//
// Every failure comes back as a status and a message, never as an exception crossing into
// JavaScript: a malformed body is a WireError whose message names the field ("group: ..."), as
// decode_group's would; running out of memory is reported likewise.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <new>
#include <span>
#include <string>

#include "remote/byte_io.h"
#include "remote/cell_codec.h"

static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "positions and normals are float xyz");

namespace {

// What cells_decode returns.
constexpr int kCellsOk = 0, kCellsMalformed = 1, kCellsOutOfMemory = 2;

// The last decode's mesh, or its error: what the accessors read.
isowall::Mesh g_mesh;
std::string g_error;
bool g_stepped = false;

}  // namespace

extern "C" {

// Decodes the `size` bytes at `body` (a cells body, past its zstd frame) at isovalue `iso`; the
// body must be whole: trailing bytes are an error, as in decode_group. With has_exact, the
// `exact_size` bytes at `exact` are its gradients' exact values (an ExactMsg's bits).
int cells_decode(const std::uint8_t* body, std::size_t size, double iso, const std::uint8_t* exact,
                 std::size_t exact_size, int has_exact) {
    g_mesh = {};
    g_error.clear();
    g_stepped = false;
    try {
        isowall::remote::ByteReader r(std::span(body, size), "group");
        const std::span<const std::uint8_t> bits(exact, exact_size);
        g_mesh =
            isowall::remote::decode_cell_body(r, iso, {has_exact ? &bits : nullptr, &g_stepped});
        r.finish();
        return kCellsOk;
    } catch (const isowall::WireError& e) {
        g_mesh = {};
        g_error = e.what();
        return kCellsMalformed;
    } catch (const std::bad_alloc&) {
        g_mesh = {};
        g_error = "group: cells: out of memory";
        return kCellsOutOfMemory;
    }
}

// The decoded mesh: vertex count V, then 3V floats of positions and of normals, and the index
// count (three a triangle) and the indices.
std::uint32_t cells_vertex_count() {
    return static_cast<std::uint32_t>(g_mesh.vertex_count());
}
const float* cells_positions() {
    return reinterpret_cast<const float*>(g_mesh.positions.data());
}
const float* cells_normals() {
    return reinterpret_cast<const float*>(g_mesh.normals.data());
}
std::uint32_t cells_index_count() {
    return static_cast<std::uint32_t>(g_mesh.indices.size());
}
const std::uint32_t* cells_indices() {
    return g_mesh.indices.data();
}
// Whether the last body decoded had its gradients' voxels to a step (exact values may follow).
int cells_stepped() {
    return g_stepped ? 1 : 0;
}
// The last failure's message, empty after a success.
const char* cells_error() {
    return g_error.c_str();
}

// Room for a body in the module's memory (the page copies each body in, then frees it).
std::uint8_t* cells_alloc(std::size_t size) {
    return new (std::nothrow) std::uint8_t[size];
}
void cells_free(std::uint8_t* p) {
    delete[] p;
}

}  // extern "C"
