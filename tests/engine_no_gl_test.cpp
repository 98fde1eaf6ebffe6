// The engine on its own floor: a frame cast into a sink that only records, in an executable that
// links no GL back end (tests/CMakeLists.txt: engine_no_gl_test links isowall_engine alone, and
// engine_links_no_gl checks its libraries). Drawing is a sink's business, not the engine's.
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>

#include "engine/progressive_engine.h"
#include "extract/group_sink.h"
#include "extract/surface_extractor.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

FrameView front_view(const Volume& v, int w, int h, double iso) {
    FrameView fv;
    fv.width = w;
    fv.height = h;
    fv.iso = iso;
    fv.camera = fit_depth_range(front_full_view(v.bounds(), float(w) / float(h)), v.bounds());
    fv.frustum = fv.camera.frustum(float(w) / float(h));
    return fv;
}

// A frame of the phantom's skin into `sink`, stopped before it starts when `stopped`.
FrameResult record_frame(RecordingSink& sink, bool stopped) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    ProgressiveEngine engine(*ex);
    const FrameView fv = front_view(p, 96, 72, kPhantomSkinIso);
    const std::atomic<bool> stop{stopped};
    return engine.run(fv, fv.screen(), sink, stop);
}

TEST(EngineNoGl, AFrameIntoARecordingSinkCastsEveryRayAndFindsTheSurface) {
    RecordingSink sink;
    const FrameResult fr = record_frame(sink, false);
    ASSERT_TRUE(fr.completed);
    EXPECT_EQ(fr.rays_cast, fr.screen_pixels) << "every pixel to cast had its ray";
    ASSERT_GT(sink.groups.size(), 0u);
    EXPECT_EQ(sink.groups.size(), fr.group_count);
    std::size_t triangles = 0;
    for (const Group& g : sink.groups) triangles += g.mesh.triangle_count();
    EXPECT_GT(triangles, 0u);
    EXPECT_TRUE(fr.final_image.rgba.empty()) << "nothing was drawn, so there is no image";
}

TEST(EngineNoGl, AStoppedFrameHandsNothingToItsSink) {
    RecordingSink sink;
    const FrameResult fr = record_frame(sink, true);
    EXPECT_FALSE(fr.completed);
    EXPECT_TRUE(sink.groups.empty());
}

}  // namespace
}  // namespace isowall
