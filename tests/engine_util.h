#pragma once
// Helpers shared by the engine tests: views of a volume and the full-surface reference image.
#include "engine/progressive_engine.h"
#include "extract/surface_extractor.h"
#include "render/renderer.h"
#include "volume/volume.h"

namespace isowall::test {

// The front full view of `v` on a w x h screen, turned by yaw/pitch and zoomed, at `iso`.
inline FrameView make_view(const Volume& v, int w, int h, double iso, float yaw = 0,
                           float pitch = 0, float zoom_factor = 1.0f) {
    FrameView fv;
    fv.width = w;
    fv.height = h;
    fv.iso = iso;
    Camera c = orbit(front_full_view(v.bounds(), float(w) / float(h)), yaw, pitch);
    if (zoom_factor != 1.0f) c = zoom(c, zoom_factor);
    fv.camera = fit_depth_range(c, v.bounds());
    fv.frustum = fv.camera.frustum(float(w) / float(h));
    return fv;
}

// Every triangle of the surface drawn in one go: what the progressive image must end up as.
inline Image full_surface_image(SurfaceExtractor& ex, Renderer& r, const FrameView& fv) {
    return draw_alone(r, ex.full_surface(fv), fv);
}

}  // namespace isowall::test
