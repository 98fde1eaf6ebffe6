// Drawn, the triangles that cover no pixel centre change nothing: the frame with them and the
// frame without them are the same, colour and depth, bit for bit; and where cells are smaller than
// a pixel most triangles are of that kind.
#include <gtest/gtest.h>

#include <iostream>

#include "extract/surface_extractor.h"
#include "render/renderer.h"
#include "render/renderer_sink.h"
#include "tests/engine_util.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

Image drawn(Renderer& r, const Mesh& mesh, const FrameView& fv, bool every_triangle,
            std::size_t& kept) {
    RendererSink sink(r, every_triangle);
    sink.begin(fv);
    Group g;
    g.mesh = mesh;
    sink.add(g);
    Image out;
    sink.read_back(out);
    kept = sink.drawn_triangles();
    EXPECT_EQ(sink.given_triangles(), mesh.triangle_count());
    return out;
}

TEST(SampleCullDraw, LeavingOutTrianglesThatCoverNoCentreChangesNoPixel) {
    const Volume v = make_phantom();
    auto ex = make_surface_extractor(v, {}, nullptr, ThreadBudget{1});
    auto renderer = make_renderer("osmesa");
    // 200x184x168 voxels on 80x60 pixels: cells of about a third of a pixel. Perspective and
    // orthographic, front and turned.
    for (const auto& [yaw, projection] :
         {std::pair{0.0f, Projection::perspective}, std::pair{35.0f, Projection::perspective},
          std::pair{20.0f, Projection::orthographic}}) {
        FrameView fv = test::make_view(v, 80, 60, 50.0, yaw, 10);
        fv.camera.projection = projection;
        fv.frustum.projection = projection;
        const Mesh mesh = ex->extract_full(fv.iso);
        std::size_t all = 0, some = 0;
        const Image every = drawn(*renderer, mesh, fv, true, all);
        const Image culled = drawn(*renderer, mesh, fv, false, some);
        EXPECT_EQ(all, mesh.triangle_count());
        EXPECT_LT(some, all / 2)
            << "most triangles of a surface finer than the pixels cover no centre";
        EXPECT_GT(some, 0u);
        EXPECT_EQ(culled.rgba, every.rgba) << "yaw " << yaw;
        EXPECT_EQ(culled.depth, every.depth) << "yaw " << yaw;
        std::cout << "  yaw " << yaw << ": " << some << " of " << all << " triangles drawn\n";
    }
}

}  // namespace
}  // namespace isowall
