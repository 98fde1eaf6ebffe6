#!/usr/bin/python3
"""Generate extract/mc_tables.h, the marching-cubes case tables.

Usage:
    /usr/bin/python3 scripts/gen_mc_tables.py > extract/mc_tables.h
    /usr/bin/python3 scripts/gen_mc_tables.py --out extract/mc_tables.h

The triangle table is derived, not typed: every cube face decides its own boundary
segments from its four corner signs alone, the segments chain into closed loops, and each
loop is triangulated as a fan. Two cells that share a face see the same four signs, so they
put the same segments on it (with opposite direction) and the mesh has no cracks.

Output is deterministic: the same script always prints the same header, byte for byte.
"""

import argparse
import sys

NUM_CORNERS = 8
NUM_EDGES = 12
NUM_CASES = 256


def corner_offset(c):
    return (c & 1, (c >> 1) & 1, (c >> 2) & 1)


# Edges 0-3 along x, 4-7 along y, 8-11 along z; (lower corner, upper corner).
EDGE_CORNERS = [
    (0, 1), (2, 3), (4, 5), (6, 7),
    (0, 2), (1, 3), (4, 6), (5, 7),
    (0, 4), (1, 5), (2, 6), (3, 7),
]  # fmt: skip
EDGE_AXIS = [0] * 4 + [1] * 4 + [2] * 4


def edge_between(a, b):
    key = (min(a, b), max(a, b))
    return EDGE_CORNERS.index(key)


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def make_faces():
    """The six faces as corner lists, counter-clockwise seen from outside the cube.

    Order: -x, +x, -y, +y, -z, +z. The orientation is checked, not assumed: the normal of
    the corner cycle must agree with the outward normal.
    """
    faces = []
    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for side in (0, 1):
            # Walk the unit square in the (u, v) plane: (0,0) (1,0) (1,1) (0,1).
            cycle = []
            for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                bits = [0, 0, 0]
                bits[axis], bits[u], bits[v] = side, du, dv
                cycle.append(bits[0] | (bits[1] << 1) | (bits[2] << 2))
            p = [corner_offset(c) for c in cycle]
            normal = cross(sub(p[1], p[0]), sub(p[2], p[1]))
            outward = [0, 0, 0]
            outward[axis] = 1 if side else -1
            if dot(normal, outward) < 0:
                cycle.reverse()
            p = [corner_offset(c) for c in cycle]
            assert dot(cross(sub(p[1], p[0]), sub(p[2], p[1])), outward) > 0
            faces.append(cycle)
    return faces


FACES = make_faces()


def inside(case, c):
    return (case >> c) & 1 == 1


def face_segments(case, face):
    """Directed segments (edge id, edge id) this face carries for this case.

    Walking the face counter-clockwise, each out->in crossing is paired with the next
    crossing. On an ambiguous face (signs alternate) this cuts off the inside corners.
    """
    crossings = []  # (edge id, enters inside)
    for i in range(4):
        a, b = face[i], face[(i + 1) % 4]
        if inside(case, a) != inside(case, b):
            crossings.append((edge_between(a, b), inside(case, b)))
    segments = []
    for i, (edge, enters) in enumerate(crossings):
        if enters:
            segments.append((edge, crossings[(i + 1) % len(crossings)][0]))
    return segments


def case_loops(case):
    """Closed loops of edge ids, each started at its smallest edge id."""
    succ = {}
    for face in FACES:
        for a, b in face_segments(case, face):
            assert a not in succ, f"case {case}: edge {a} starts two segments"
            succ[a] = b
    assert sorted(succ) == sorted(succ.values()), f"case {case}: open chain"
    loops = []
    seen = set()
    for start in sorted(succ):
        if start in seen:
            continue
        loop = [start]
        seen.add(start)
        e = succ[start]
        while e != start:
            loop.append(e)
            seen.add(e)
            e = succ[e]
        loops.append(loop)
    return loops


def fan(loop, reverse):
    tris = []
    for i in range(1, len(loop) - 1):
        tri = (loop[0], loop[i], loop[i + 1])
        tris.append((tri[0], tri[2], tri[1]) if reverse else tri)
    return tris


def edge_midpoint(e):
    a, b = (corner_offset(c) for c in EDGE_CORNERS[e])
    return tuple((x + y) / 2 for x, y in zip(a, b))


def triangle_normal(tri):
    p0, p1, p2 = (edge_midpoint(e) for e in tri)
    return cross(sub(p1, p0), sub(p2, p0))


def choose_reverse():
    """Whether loop order must be reversed so normals point from inside to outside.

    Decided on case 1 (corner 0 alone inside): its one triangle must face away from corner 0.
    """
    (loop,) = case_loops(1)
    n = triangle_normal(fan(loop, reverse=False)[0])
    away = sub(edge_midpoint(loop[0]), corner_offset(0))
    return dot(n, away) < 0


def build_tables():
    reverse = choose_reverse()
    table = []
    for case in range(NUM_CASES):
        tris = []
        for loop in case_loops(case):
            tris.extend(fan(loop, reverse))
        table.append(tris)
    (tri,) = table[1]
    assert dot(triangle_normal(tri), sub(edge_midpoint(tri[0]), corner_offset(0))) > 0
    return table


def check_tables(table):
    for case, tris in enumerate(table):
        crossed = {
            e for e, (a, b) in enumerate(EDGE_CORNERS) if inside(case, a) != inside(case, b)
        }
        used = {e for tri in tris for e in tri}
        assert used == crossed, f"case {case}: uses {used}, crosses {crossed}"
    assert not table[0] and not table[NUM_CASES - 1]


# Derived tables and compile-time checks. Fixed text: these are computed from the tables
# above by the compiler, so a hand edit of the generated tables cannot go unnoticed.
DERIVED_AND_CHECKS = """\
namespace detail {

constexpr bool corner_inside(int mc_case, int corner) {
    return (mc_case >> corner) & 1;
}

constexpr std::array<std::uint16_t, 256> make_edge_mask() {
    std::array<std::uint16_t, 256> mask{};
    for (int c = 0; c < 256; ++c) {
        for (int e = 0; e < 12; ++e) {
            if (corner_inside(c, kEdgeCorners[e][0]) != corner_inside(c, kEdgeCorners[e][1])) {
                mask[c] = static_cast<std::uint16_t>(mask[c] | (1u << e));
            }
        }
    }
    return mask;
}

}  // namespace detail

// kEdgeMask[case] = bit e set when edge e has a sign change (the case puts a vertex on it).
// Derived from kEdgeCorners rather than generated, so the two cannot disagree.
inline constexpr std::array<std::uint16_t, 256> kEdgeMask = detail::make_edge_mask();

namespace detail {

// Every row holds exactly kTriangleCount triangles of valid edge ids, then only -1.
constexpr bool rows_well_formed() {
    int max_count = 0;
    for (int c = 0; c < 256; ++c) {
        const int n = 3 * kTriangleCount[c];
        if (kTriangleCount[c] > max_count) max_count = kTriangleCount[c];
        for (int i = 0; i < 3 * kMaxTriangles + 1; ++i) {
            const int e = kTriangleEdges[c][i];
            if (i < n ? (e < 0 || e >= 12) : e != -1) return false;
        }
    }
    return max_count == kMaxTriangles;
}

// The edges the triangles use are exactly the edges that change sign.
constexpr bool triangles_use_crossed_edges() {
    for (int c = 0; c < 256; ++c) {
        unsigned used = 0;
        for (int i = 0; i < 3 * kTriangleCount[c]; ++i) used |= 1u << kTriangleEdges[c][i];
        if (used != kEdgeMask[c]) return false;
    }
    return true;
}

// Flipping every sign keeps every sign change, so c and 255 - c cross the same edges.
constexpr bool complements_share_edges() {
    for (int c = 0; c < 256; ++c) {
        if (kEdgeMask[c] != kEdgeMask[255 - c]) return false;
    }
    return true;
}

}  // namespace detail

static_assert(kTriangleCount[0] == 0 && kTriangleEdges[0][0] == -1, "case 0 is all outside");
static_assert(kTriangleCount[255] == 0 && kTriangleEdges[255][0] == -1, "case 255 is all inside");
static_assert(detail::rows_well_formed(), "rows hold kTriangleCount triangles then -1");
static_assert(detail::triangles_use_crossed_edges(), "triangles use exactly kEdgeMask edges");
static_assert(detail::complements_share_edges(), "case c and 255 - c cross the same edges");
"""


def emit(table):
    max_tris = max(len(t) for t in table)
    width = 3 * max_tris + 1
    out = []
    w = out.append
    w("// DO NOT EDIT: generated by scripts/gen_mc_tables.py")
    w("// Regenerate: /usr/bin/python3 scripts/gen_mc_tables.py --out extract/mc_tables.h")
    w("#pragma once")
    w("// Marching-cubes tables. Conventions the extractor relies on:")
    w("//  - corner c sits at offset (c & 1, (c >> 1) & 1, (c >> 2) & 1);")
    w("//  - case index = sum of (1 << c) over corners that are inside (value >= isovalue);")
    w("//  - edges 0-3 run along x, 4-7 along y, 8-11 along z, stored (lower, upper) corner;")
    w("//  - triangles are counter-clockwise seen from outside the inside region, so the")
    w("//    geometric normal points from high values toward low values.")
    w("// The triangle table is crack-free: each cube face chooses its boundary segments from")
    w("// its four corner signs alone (ambiguous faces cut off their inside corners), so two")
    w("// cells sharing a face put the same segments on it and a closed surface stays closed.")
    w("#include <array>")
    w("#include <cstdint>")
    w("")
    w("namespace isowall::mc {")
    w("")
    w("// kCornerOffset[corner] = {x, y, z} offset of that corner within the cell, each 0 or 1.")
    w("inline constexpr std::array<std::array<std::uint8_t, 3>, 8> kCornerOffset = {{")
    for c in range(NUM_CORNERS):
        x, y, z = corner_offset(c)
        w(f"    {{{x}, {y}, {z}}},  // corner {c}")
    w("}};")
    w("")
    w("// kEdgeCorners[edge] = {lower corner, upper corner}; they differ only in bit")
    w("// kEdgeAxis[edge], and the lower one has that bit clear.")
    w("inline constexpr std::array<std::array<std::uint8_t, 2>, 12> kEdgeCorners = {{")
    for e, (a, b) in enumerate(EDGE_CORNERS):
        w(f"    {{{a}, {b}}},  // edge {e}")
    w("}};")
    w("")
    w("// kEdgeAxis[edge] = axis the edge runs along: 0 = x, 1 = y, 2 = z.")
    w("inline constexpr std::array<std::uint8_t, 12> kEdgeAxis = {")
    w("    " + ", ".join(str(a) for a in EDGE_AXIS) + ",")
    w("};")
    w("")
    w("// Largest triangle count over all 256 cases; sizes each kTriangleEdges row.")
    w(f"inline constexpr int kMaxTriangles = {max_tris};")
    w("")
    # Keep one row per case (and 16 counts per row) so a case is found by its line comment.
    w("// clang-format off")
    w("// kTriangleCount[case] = number of triangles the case emits.")
    w("inline constexpr std::array<std::uint8_t, 256> kTriangleCount = {")
    for row in range(0, NUM_CASES, 16):
        w("    " + ", ".join(str(len(table[c])) for c in range(row, row + 16)) + ",")
    w("};")
    w("")
    w("// kTriangleEdges[case] = edge ids, three per triangle (vertices lie on those edges),")
    w("// counter-clockwise seen from outside; -1 after the last triangle and in unused slots.")
    w("inline constexpr std::array<std::array<std::int8_t, 3 * kMaxTriangles + 1>, 256>")
    w("    kTriangleEdges = {{")
    for case, tris in enumerate(table):
        ids = [e for tri in tris for e in tri]
        ids += [-1] * (width - len(ids))
        w("        {" + ", ".join(str(e) for e in ids) + f"}},  // case {case}")
    w("    }};")
    w("// clang-format on")
    w("")
    out.append(DERIVED_AND_CHECKS)
    w("}  // namespace isowall::mc")
    return "\n".join(out) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", help="write the header here instead of stdout")
    args = parser.parse_args()
    table = build_tables()
    check_tables(table)
    text = emit(table)
    if args.out:
        with open(args.out, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
