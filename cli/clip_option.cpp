#include "cli/clip_option.h"

#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/number.h"

namespace isowall {

void add_clip_options(CLI::App& cmd, ClipOptions& clip) {
    cmd.add_option("--clip", clip.planes,
                   "Clip plane over voxel indices, keeping one side: x<N, y>N, z<N, or A,B,C<D "
                   "(A*x + B*y + C*z below D); repeat for more planes")
        ->type_name("PLANE");
    cmd.add_option("--clip-box", clip.box,
                   "Keep only the box X0,Y0,Z0,X1,Y1,Z1 (voxel indices): six clip planes")
        ->type_name("X0,Y0,Z0,X1,Y1,Z1");
}

namespace {

ClipSet box_of(const std::string& text) {
    std::vector<double> v;
    std::stringstream in(text);
    std::string part;
    while (std::getline(in, part, ',')) {
        const auto x = parse_number(part);
        if (!x || !limits::kCoordinate.contains(*x))
            throw InputError(
                "--clip-box", "value",
                "expected six numbers X0,Y0,Z0,X1,Y1,Z1 in [-1e6, 1e6], got '" + text + "'");
        v.push_back(*x);
    }
    if (v.size() != 6)
        throw InputError("--clip-box", "value",
                         "expected six numbers X0,Y0,Z0,X1,Y1,Z1, got '" + text + "'");
    std::string problem;
    const auto box = clip_box(glm::vec3(v[0], v[1], v[2]), glm::vec3(v[3], v[4], v[5]), problem);
    if (!box) throw InputError("--clip-box", "value", problem);
    return *box;
}

}  // namespace

ClipSet checked_clip(const ClipOptions& clip) {
    ClipSet out = clip.box.empty() ? ClipSet{} : box_of(clip.box);
    for (const std::string& text : clip.planes) {
        std::string problem;
        const auto plane = parse_clip_plane(text, problem);
        if (!plane) throw InputError("--clip", "value", problem);
        if (!out.add(*plane))
            throw InputError("--clip", "value",
                             "at most " + std::to_string(kMaxClipPlanes) +
                                 " planes (a box is six), got more at '" + text + "'");
    }
    return out;
}

void check_clip_keeps(const ClipSet& clip, glm::ivec3 dims, const std::string& where,
                      const std::string& field) {
    if (!keeps_some_voxel(clip, dims))
        throw InputError(where, field,
                         "the clip planes keep nothing of the volume's voxels (0,0,0) - (" +
                             std::to_string(dims.x - 1) + "," + std::to_string(dims.y - 1) + "," +
                             std::to_string(dims.z - 1) + ")");
}

}  // namespace isowall
