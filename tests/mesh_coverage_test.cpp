// add_mesh_coverage (progressive/mesh_coverage.h): the pixels a mesh covers, found on the
// CPU, are the renderer's covered pixels but for a few along the silhouette, in both projections
// and in a region of the screen; the dynamic grid sizes its grid from them.
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "engine/progressive_engine.h"
#include "extract/group_sink.h"
#include "progressive/mesh_coverage.h"
#include "render/renderer_sink.h"
#include "tests/engine_util.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

struct Agreement {
    std::size_t both = 0, either = 0;
};

Agreement agree(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    Agreement g;
    for (std::size_t i = 0; i < a.size(); ++i) {
        g.both += a[i] && b[i];
        g.either += a[i] || b[i];
    }
    return g;
}

TEST(MeshCoverage, IsTheRenderersCoverageButForTheSilhouette) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    auto r = make_renderer("osmesa");
    for (const Projection projection : {Projection::perspective, Projection::orthographic}) {
        SCOPED_TRACE(projection == Projection::perspective ? "perspective" : "orthographic");
        FrameView fv = test::make_view(p, 320, 240, kPhantomSkinIso, 25, -15);
        if (projection == Projection::orthographic) {
            fv.camera.projection = Projection::orthographic;
            fv.camera.ortho_height = p.bounds().extent().y * 1.2f;
            fv.frustum = fv.camera.frustum(320.0f / 240.0f);
        }
        Group g;
        g.mesh = ex->extract_full(fv.iso);
        RendererSink sink(*r);
        sink.begin(fv);
        sink.add(g);
        for (const PixelRect rect : {PixelRect{0, 0, 320, 240}, PixelRect{70, 40, 150, 110}}) {
            std::vector<std::uint8_t> gl;
            sink.coverage(gl, rect);
            ASSERT_EQ(gl.size(), std::size_t(rect.width) * std::size_t(rect.height));
            std::vector<std::uint8_t> cpu(gl.size(), 0);
            add_mesh_coverage(g.mesh, fv.camera.view(), fv.frustum, fv.width, fv.height, rect, cpu);
            const Agreement a = agree(gl, cpu);
            ASSERT_GT(a.both, 2000u);
            // Pixel centres exactly on an edge may go either way; nothing else may differ.
            EXPECT_GE(double(a.both) / double(a.either), 0.995) << a.both << " of " << a.either;
        }
    }
}

TEST(MeshCoverage, AddsToWhatIsThereAndLeavesOutWhatTheRendererClips) {
    // One triangle in front of the eye (view space z = -5) over the middle of the screen, one
    // behind it: only the first covers anything.
    Frustum f;  // perspective, near 0.1, far 100: the triangle spans about 0.8 of the screen
    f.left = f.bottom = -0.05f;
    f.right = f.top = 0.05f;
    Mesh m;
    m.positions = {{-1, -1, -5}, {1, -1, -5}, {0, 1, -5}, {-1, -1, 5}, {1, -1, 5}, {0, 1, 5}};
    m.normals.assign(6, glm::vec3(0, 0, 1));
    m.indices = {0, 1, 2};
    const glm::mat4 view(1.0f);
    const PixelRect rect{0, 0, 64, 64};
    std::vector<std::uint8_t> covered(64 * 64, 0);
    covered[0] = 1;  // kept: coverage is added
    add_mesh_coverage(m, view, f, 64, 64, rect, covered);
    std::size_t n = 0;
    for (std::uint8_t c : covered) n += c;
    EXPECT_EQ(covered[0], 1);
    EXPECT_GT(n, 300u);
    EXPECT_EQ(covered[32 * 64 + 32], 1);  // the centre

    m.indices = {3, 4, 5};  // behind the eye
    std::vector<std::uint8_t> none(64 * 64, 0);
    add_mesh_coverage(m, view, f, 64, 64, rect, none);
    for (std::uint8_t c : none) ASSERT_EQ(c, 0);

    std::vector<std::uint8_t> wrong(10, 0);
    EXPECT_THROW(add_mesh_coverage(m, view, f, 64, 64, rect, wrong), std::invalid_argument);
}

// A sink with no renderer cannot tell coverage; the dynamic grid now sizes its grid from the
// groups' own pixels all the same, so it leaves its search after the first hit.
TEST(MeshCoverage, DynamicGridSizesWithoutARenderer) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    auto r = make_renderer("osmesa");
    const FrameView fv = test::make_view(p, 200, 150, kPhantomSkinIso);
    ProgressiveEngine engine(*ex);
    const std::atomic<bool> stop{false};
    EngineFrame frame(engine, fv, stop);
    RecordingSink recorded;
    RegionCursor c = frame.cursor(fv, fv.screen());
    ASSERT_TRUE(frame.cast(fv, c, recorded, 1));  // the first level: one ray, a hit
    ASSERT_GT(c.hits, 0u);
    EXPECT_FALSE(c.sizing);  // sized at once
    EXPECT_TRUE(c.drawn.empty());
    ASSERT_TRUE(frame.cast(fv, c, recorded));
    EXPECT_TRUE(c.done);
}

}  // namespace
}  // namespace isowall
