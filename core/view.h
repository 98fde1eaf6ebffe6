#pragma once
// What a frame draws: one camera and the (possibly off-axis) frustum of a screen of width x height
// pixels, at one isovalue, cut by the clip planes (core/clip.h). A wall tile's view is the wall
// camera with its tile's sub-frustum.
#include <ostream>

#include "core/camera.h"
#include "core/clip.h"

namespace isowall {

struct FrameView {
    Camera camera;
    Frustum frustum;
    int width = 0;
    int height = 0;
    double iso = 0;
    ClipSet clip{};  // voxel index coordinates; empty: the whole volume

    PixelRect screen() const { return {0, 0, width, height}; }
};

inline std::ostream& operator<<(std::ostream& os, const FrameView& v) {
    os << "FrameView{" << v.width << "x" << v.height << ", iso " << v.iso << ", " << v.camera
       << ", " << v.frustum;
    if (!v.clip.empty()) os << ", " << v.clip;
    return os << "}";
}

}  // namespace isowall
