// Several surfaces drawn together (app/surfaces_frame.h): the progressive picture ends as the
// full surfaces' layers composited, on one thread and two, and its replayed timeline ends at
// C = 1 with every surface's groups.
#include <gtest/gtest.h>

#include <memory>

#include "app/surfaces_frame.h"
#include "core/surface_style.h"
#include "tests/engine_util.h"
#include "tests/image_compare.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

struct Parts {
    std::vector<std::unique_ptr<SurfaceExtractor>> extractors;
    std::vector<std::unique_ptr<Renderer>> renderers;
    std::vector<std::unique_ptr<ProgressiveEngine>> engines;
    std::vector<SurfaceLayer> layers;
};

// The skin at 0.3 over the opaque bone, in the program's order (core/surface_style.h).
std::vector<SurfaceStyle> skin_over_bone() {
    SurfaceStyle skin, bone;
    skin.iso = kPhantomSkinIso;
    skin.opacity = 0.3f;
    bone.iso = kPhantomBoneIso;
    return canonical_order({bone, skin});
}

Parts parts(const SurfaceExtractor& ex, const std::vector<SurfaceStyle>& styles, int threads) {
    Parts p;
    for (const SurfaceStyle& s : styles) {
        p.extractors.push_back(ex.share());
        p.renderers.push_back(make_renderer("osmesa"));
        EngineOptions opt;
        opt.threads = threads;
        p.engines.push_back(std::make_unique<ProgressiveEngine>(*p.extractors.back(), opt));
        p.layers.push_back({p.engines.back().get(), p.renderers.back().get(), s});
    }
    return p;
}

TEST(Surfaces, TheFinalPictureIsTheFullSurfacesCompositedOnOneThreadAndTwo) {
    const Volume v = make_phantom();
    auto ex = make_surface_extractor(v, {}, nullptr, ThreadBudget{2});
    const FrameView fv = test::make_view(v, 160, 120, kPhantomSkinIso, 30, 20);
    const std::vector<SurfaceStyle> styles = skin_over_bone();
    Parts full_parts = parts(*ex, styles, 1);
    std::vector<Mesh> meshes;
    for (const SurfaceStyle& s : styles) {
        FrameView at = fv;
        at.iso = s.iso;
        meshes.push_back(ex->full_surface(at));
    }
    const Image full = draw_surfaces_alone(full_parts.layers, meshes, fv);
    // The skin alone differs from the composite: the test would see a surface left out.
    ASSERT_LT(
        test::compare_images(full, draw_alone(*full_parts.renderers[0], meshes[0], fv)).equal_share,
        0.9);
    for (const int threads : {1, 2}) {
        Parts p = parts(*ex, styles, threads);
        SurfacesFrame sf = draw_surfaces(p.layers, fv);
        ASSERT_TRUE(sf.frame.completed);
        ASSERT_EQ(sf.layers.size(), 2u);
        for (const FrameResult& l : sf.layers) EXPECT_GT(l.group_count, 0u);
        const test::ImageComparison c = test::compare_images(sf.frame.final_image, full);
        EXPECT_GE(c.mask_iou, 0.999) << threads << " threads: " << c;
        EXPECT_GE(c.equal_share, 0.999) << threads << " threads: " << c;

        measure_surfaces(sf, p.layers, fv);
        ASSERT_FALSE(sf.frame.timeline.empty());
        EXPECT_DOUBLE_EQ(sf.frame.timeline.back().correctness.c, 1.0);
        EXPECT_EQ(sf.frame.timeline.back().groups, sf.frame.group_count);
        for (std::size_t k = 0; k < 2; ++k)
            EXPECT_EQ(sf.shown.back()[k], sf.layers[k].groups.size());
        for (std::size_t i = 1; i < sf.frame.timeline.size(); ++i) {
            EXPECT_GE(sf.frame.timeline[i].time_s, sf.frame.timeline[i - 1].time_s);
            EXPECT_GE(sf.frame.timeline[i].groups, sf.frame.timeline[i - 1].groups);
        }
    }
}

// A stop before the frame begins ends it at once, incomplete, with no picture.
TEST(Surfaces, AStoppedFrameEndsIncomplete) {
    const Volume v = make_phantom();
    auto ex = make_surface_extractor(v);
    const FrameView fv = test::make_view(v, 64, 48, kPhantomSkinIso);
    Parts p = parts(*ex, skin_over_bone(), 1);
    const std::atomic<bool> stop{true};
    const SurfacesFrame sf = draw_surfaces(p.layers, fv, &stop);
    EXPECT_FALSE(sf.frame.completed);
    EXPECT_EQ(sf.frame.final_image.pixel_count(), 0u);
}

}  // namespace
}  // namespace isowall
