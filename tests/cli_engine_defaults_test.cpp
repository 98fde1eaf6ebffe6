// The command line's engine options default to the engine's own: a default chosen over every
// shared volume (extract/propagator.h) is what `render`, `wall` and `serve` use. Before
// this test, EngineCli kept a max count of its own (2000, chosen on one volume) while the engine's
// was 1000.
#include <gtest/gtest.h>

#include <cmath>

#include "cli/engine_cli.h"

namespace isowall {
namespace {

TEST(CliEngineDefaults, AreTheEnginesOwn) {
    const EngineOptions cli = to_engine_options(EngineCli{});
    const EngineOptions engine;
    EXPECT_EQ(cli.order, engine.order);
    EXPECT_EQ(cli.intersect, engine.intersect);
    EXPECT_EQ(cli.propagation.mode, engine.propagation.mode);
    EXPECT_EQ(cli.propagation.max_count, engine.propagation.max_count);
    EXPECT_NEAR(cli.propagation.cutoff_rad, engine.propagation.cutoff_rad, 1e-6);
    EXPECT_NEAR(cli.propagation.foldback_rad, engine.propagation.foldback_rad, 1e-6);
    EXPECT_EQ(cli.propagation.interpolant_cache, engine.propagation.interpolant_cache);
    EXPECT_EQ(cli.propagation.facing_only, engine.propagation.facing_only);
    EXPECT_EQ(cli.screen_box, engine.screen_box);
    EXPECT_EQ(cli.screen_mask, engine.screen_mask);
    EXPECT_EQ(cli.frontier_seeds, engine.frontier_seeds);
    EXPECT_EQ(cli.adaptive, engine.adaptive);
    EXPECT_EQ(cli.adaptive_max_level, engine.adaptive_max_level);
    EXPECT_EQ(cli.adaptive_pixels, engine.adaptive_pixels);
    EXPECT_EQ(cli.adaptive_refine, engine.adaptive_refine);
    EXPECT_EQ(cli.sampled_triangles, engine.sampled_triangles);
    EXPECT_EQ(std::isinf(cli.adaptive_error_px), std::isinf(engine.adaptive_error_px));
}

}  // namespace
}  // namespace isowall
