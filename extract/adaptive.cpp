#include "extract/adaptive.h"

#include <algorithm>
#include <cmath>

namespace isowall {

ResolutionLevels resolution_levels(const Camera& camera, const Frustum& frustum, int height_px,
                                   glm::vec3 spacing, int max_level, float pixels, float error_px) {
    ResolutionLevels r;
    r.eye = camera.eye;
    r.max_level = std::clamp(max_level, 0, kMaxMetaLevel);
    if (height_px <= 0 || !(frustum.height() > 0) || !(pixels > 0))
        return r;  // no pixels: nothing to coarsen
    const float pixel = frustum.height() / static_cast<float>(height_px);
    r.error_px = error_px;
    if (frustum.projection == Projection::perspective)
        r.pixel_slope = frustum.near_z > 0 ? pixel / frustum.near_z : 0.0f;
    else
        r.pixel_size = pixel;
    const float s_max = std::max({spacing.x, spacing.y, spacing.z});
    const float px = pixels * frustum.height() / static_cast<float>(height_px);
    for (int i = 0; i <= kMaxMetaLevel; ++i) {
        const float size = std::ldexp(s_max, i);
        float& d = r.d[static_cast<std::size_t>(i)];
        if (frustum.projection == Projection::perspective)
            d = frustum.near_z > 0 ? size / (px / frustum.near_z)
                                   : std::numeric_limits<float>::infinity();
        else
            d = size < px ? 0.0f : std::numeric_limits<float>::infinity();
    }
    return r;
}

std::ostream& operator<<(std::ostream& os, const ResolutionLevels& r) {
    os << "ResolutionLevels{D=[";
    for (std::size_t i = 0; i < r.d.size(); ++i) os << (i ? " " : "") << r.d[i];
    return os << "] eye=(" << r.eye.x << "," << r.eye.y << "," << r.eye.z
              << ") max_level=" << r.max_level << "}";
}

}  // namespace isowall
