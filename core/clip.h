#pragma once
// Clip planes: the half-spaces a picture keeps. An operator cuts a volume open with a plane (or
// six, a box) to see inside; every part of isowall that makes the picture honours the same set:
// rays start where they enter the kept space, propagation never enters a unit wholly cut away, and
// triangles are cut at the planes (clip_mesh), so no drawn triangle reaches past one. Where the cut
// opens a closed surface its inside shows through, drawn in the back-face colour (headlight.frag).
//
// A FrameView carries its planes in voxel index coordinates, as the operator gives them (`x<120`
// on any volume means the same slice whatever its spacing); in_object_space() turns them into the
// object space of rays and meshes.
#include <array>
#include <cstddef>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/box.h"
#include "core/mesh.h"
#include "core/ray.h"

namespace isowall {

// Keeps the points p with dot(normal, p) >= at.
struct ClipPlane {
    glm::vec3 normal{0, 0, 1};
    float at = 0;

    float side(glm::vec3 p) const { return glm::dot(normal, p) - at; }
    friend bool operator==(const ClipPlane&, const ClipPlane&) = default;
};

// A box and two planes more: the most any picture needs, and a bound for a message to check.
inline constexpr std::size_t kMaxClipPlanes = 8;

struct ClipSet {
    std::array<ClipPlane, kMaxClipPlanes> planes{};
    std::size_t count = 0;

    bool empty() const { return count == 0; }
    const ClipPlane* begin() const { return planes.data(); }
    const ClipPlane* end() const { return planes.data() + count; }
    // False when the set is full.
    bool add(const ClipPlane& p);
    bool keeps(glm::vec3 p) const;
    friend bool operator==(const ClipSet& a, const ClipSet& b);
};

std::ostream& operator<<(std::ostream& os, const ClipSet& c);

// `voxel` (planes over voxel indices) in object space, where a voxel index i sits at i * spacing.
ClipSet in_object_space(const ClipSet& voxel, glm::vec3 spacing);

// True when one plane leaves every corner of `box` on its cut side: nothing in it is kept. (A box
// cut by several planes that each keep a corner may still be wholly cut; it is kept, which only
// costs a unit that clip_mesh then empties.)
bool cut_away(const ClipSet& clip, const Box3& box);

// True when every plane keeps every corner of `box`: nothing in it is cut.
bool keeps_whole(const ClipSet& clip, const Box3& box);

// False when `clip` (voxel indices) keeps no part of a volume of `dims` voxels: its picture would
// be empty. Exact, for the planes together: the box the voxels span and the kept half-spaces meet
// when some point where three of their planes cross lies in all of them (a bounded convex set
// that is not empty has such a corner).
bool keeps_some_voxel(const ClipSet& clip, glm::ivec3 dims);

// The part of `ray` (t >= 0) in the kept space: [t0, t1], t1 possibly infinite; nullopt when the
// ray never enters it.
struct RaySpan {
    float t0 = 0, t1 = 0;
};
std::optional<RaySpan> kept_span(const ClipSet& clip, const Ray& ray);

// `ray` started where it enters the kept space, and the parameter it may go to from there (the
// largest float when nothing ends it); nullopt when it never enters. The set empty: `ray` itself.
struct ClippedRay {
    Ray ray;
    float t_max = 0;
};
std::optional<ClippedRay> clip_ray(const ClipSet& clip, const Ray& ray);

// Cuts `mesh` at every plane: triangles wholly kept stay as they are, triangles wholly cut go, and
// a triangle across a plane keeps its kept part (new vertices on the plane, normals interpolated).
// Vertices no kept triangle uses are dropped. Nothing changes with an empty set.
void clip_mesh(Mesh& mesh, const ClipSet& clip);

// One plane from an operator's text, over voxel indices: `x<120`, `y>40.5`, `z<64`, or a plane of
// any direction `A,B,C<D` / `A,B,C>D` (keeps A*x + B*y + C*z below or above D). nullopt with
// `problem` set for anything else.
std::optional<ClipPlane> parse_clip_plane(std::string_view text, std::string& problem);

// The six planes keeping the box [lo, hi] (voxel indices); nullopt with `problem` set unless lo
// is below hi on every axis.
std::optional<ClipSet> clip_box(glm::vec3 lo, glm::vec3 hi, std::string& problem);

// The operator's form of `plane` (what parse_clip_plane reads back to the same plane).
std::string clip_plane_text(const ClipPlane& plane);
// Every plane of `clip` so, space-separated ("x<99 z>40"): a script's `clip` line without the word;
// empty for none.
std::string clip_text(const ClipSet& clip);

}  // namespace isowall
