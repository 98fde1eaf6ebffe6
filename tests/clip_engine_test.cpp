// The progressive engine under clip planes: no drawn triangle reaches past a plane, the final
// picture is the full surface cut by the same planes, and a pixel whose ray the planes cut away
// whole casts no ray; with footprint units and without, on one thread and two.
#include <gtest/gtest.h>

#include <cstdio>

#include "app/whole_frame.h"
#include "core/clip.h"
#include "tests/engine_util.h"
#include "tests/image_compare.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

ClipPlane plane(const char* text) {
    std::string problem;
    return parse_clip_plane(text, problem).value();
}

FrameResult run(SurfaceExtractor& ex, Renderer& r, const FrameView& fv, float footprint_px,
                int threads) {
    EngineOptions opt;
    opt.footprint_pixels = footprint_px;
    opt.threads = threads;
    ProgressiveEngine engine(ex, opt);
    FrameResult fr = draw_frame(engine, fv, r);
    EXPECT_TRUE(fr.completed);
    return fr;
}

TEST(ClipEngine, NothingPastAPlaneAndTheFinalPictureIsTheCutSurface) {
    const Volume v = make_phantom();
    auto ex = make_surface_extractor(v, {}, nullptr, ThreadBudget{2});
    auto renderer = make_renderer("osmesa");
    std::string problem;
    ClipSet half, box_and_diagonal = clip_box({30, 20, 40}, {150, 140, 120}, problem).value();
    half.add(plane("x<100"));
    box_and_diagonal.add(plane("1,0,1>150"));
    for (const ClipSet& clip : {half, box_and_diagonal}) {
        FrameView fv = test::make_view(v, 160, 120, kPhantomSkinIso, 30, 20);
        fv.clip = clip;
        const Image full = test::full_surface_image(*ex, *renderer, fv);
        const ClipSet object = in_object_space(clip, v.spacing());
        for (const float footprint : {0.0f, EngineOptions{}.footprint_pixels})
            for (const int threads : {1, 2}) {
                const FrameResult fr = run(*ex, *renderer, fv, footprint, threads);
                std::size_t triangles = 0;
                float worst = 0;
                for (const Group& g : fr.groups) {
                    triangles += g.mesh.triangle_count();
                    for (const std::uint32_t i : g.mesh.indices)
                        for (const ClipPlane& p : object)
                            worst = std::min(worst, p.side(g.mesh.positions[i]));
                }
                EXPECT_GT(triangles, 100u);
                EXPECT_GE(worst, -1e-3f) << fv << ": a vertex past a plane";
                const test::ImageComparison c = test::compare_images(fr.final_image, full);
                EXPECT_GE(c.mask_iou, 0.999) << fv << " footprint " << footprint;
                EXPECT_GE(c.equal_share, 0.99) << fv << " footprint " << footprint;
                std::printf(
                    "%s, footprint %g px, %d thread(s): %zu triangles, IoU %.5f, equal "
                    "%.5f against the cut full surface\n",
                    testing::PrintToString(clip).c_str(), footprint, threads, triangles, c.mask_iou,
                    c.equal_share);
            }
    }
}

TEST(ClipEngine, RaysTheClipCutsAwayWholeAreNeverCast) {
    const Volume v = make_phantom();
    auto ex = make_surface_extractor(v);
    auto renderer = make_renderer("osmesa");
    FrameView fv = test::make_view(v, 160, 120, kPhantomSkinIso);
    const FrameResult whole = run(*ex, *renderer, fv, 0, 1);
    ASSERT_GT(whole.rays_cast, 0u);
    // The front view looks along +y from y < 0: keeping only what lies behind the eye leaves no
    // ray anything to enter.
    fv.clip.add(plane("y<-5000"));
    const FrameResult none = run(*ex, *renderer, fv, 0, 1);
    EXPECT_EQ(none.rays_cast, 0u);
    EXPECT_TRUE(none.groups.empty());
    // The eye is at x = 99.5: keeping x < 90 leaves the rays of the right half of the screen
    // (which go towards larger x) nothing to enter, so about half the rays are cast.
    fv.clip = {};
    fv.clip.add(plane("x<90"));
    const FrameResult left = run(*ex, *renderer, fv, 0, 1);
    EXPECT_GT(left.rays_cast, 0u);
    EXPECT_LT(double(left.rays_cast), 0.7 * double(whole.rays_cast));
    std::printf("rays: %zu whole, %zu with x < 90 kept\n", whole.rays_cast, left.rays_cast);
}

}  // namespace
}  // namespace isowall
