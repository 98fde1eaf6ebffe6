#include "volume/colour_field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

namespace isowall {
namespace {

template <class T>
double trilinear(const VolumeView<T>& v, glm::vec3 p) {
    const glm::vec3 hi = glm::vec3(glm::max(v.dims - 1, glm::ivec3(0)));
    p = glm::clamp(p, glm::vec3(0), hi);
    const glm::ivec3 a = glm::min(glm::ivec3(glm::floor(p)), glm::max(v.dims - 2, glm::ivec3(0)));
    const glm::ivec3 b = glm::min(a + 1, v.dims - 1);
    const glm::vec3 f = p - glm::vec3(a);
    auto at = [&](int x, int y, int z) { return static_cast<double>(v.at(x, y, z)); };
    const double c00 = at(a.x, a.y, a.z) + f.x * (at(b.x, a.y, a.z) - at(a.x, a.y, a.z));
    const double c10 = at(a.x, b.y, a.z) + f.x * (at(b.x, b.y, a.z) - at(a.x, b.y, a.z));
    const double c01 = at(a.x, a.y, b.z) + f.x * (at(b.x, a.y, b.z) - at(a.x, a.y, b.z));
    const double c11 = at(a.x, b.y, b.z) + f.x * (at(b.x, b.y, b.z) - at(a.x, b.y, b.z));
    const double c0 = c00 + f.y * (c10 - c00), c1 = c01 + f.y * (c11 - c01);
    return c0 + f.z * (c1 - c0);
}

}  // namespace

double sample_trilinear(const Volume& v, glm::vec3 p) {
    return dispatch_voxel_type(v.type(),
                               [&](auto tag) { return trilinear(v.view<decltype(tag)>(), p); });
}

void colour_mesh(Mesh& mesh, const ColourField& field, glm::vec3 spacing) {
    mesh.colours.resize(mesh.positions.size());
    dispatch_voxel_type(field.values->type(), [&](auto tag) {
        const auto view = field.values->view<decltype(tag)>();
        for (std::size_t i = 0; i < mesh.positions.size(); ++i)
            mesh.colours[i] = field.scale.at(trilinear(view, mesh.positions[i] / spacing));
    });
}

std::pair<double, double> finite_range(const Volume& v) {
    return dispatch_voxel_type(v.type(), [&](auto tag) {
        using T = decltype(tag);
        const auto view = v.view<T>();
        T lo = std::numeric_limits<T>::max(), hi = std::numeric_limits<T>::lowest();
        bool any = false;
        auto take = [&](T d) {
            if constexpr (std::is_floating_point_v<T>)
                if (!std::isfinite(d)) return;
            lo = std::min(lo, d);
            hi = std::max(hi, d);
            any = true;
        };
        // Every rank of a wall coloured without --color-range runs this at start-up: an x-fastest
        // array in one pass; a bricked one voxel by voxel, as its partial bricks hold padding.
        if (!view.bricked()) {
            for (std::size_t i = 0, n = view.voxel_count(); i < n; ++i) take(view.data[i]);
        } else {
            for (int z = 0; z < view.dims.z; ++z)
                for (int y = 0; y < view.dims.y; ++y)
                    for (int x = 0; x < view.dims.x; ++x) take(view.at(x, y, z));
        }
        return any ? std::pair{double(lo), double(hi)} : std::pair{0.0, 0.0};
    });
}

std::string colour_field_problem(const Volume& values, const Volume& surface) {
    if (values.dims() == surface.dims()) return "";
    auto size = [](glm::ivec3 d) {
        return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
    };
    return "a field of " + size(values.dims()) + " voxels cannot colour a volume of " +
           size(surface.dims()) + ": it must lie on the same grid";
}

}  // namespace isowall
