// Golden images: fixed views of the built-in phantom (and one shared file), drawn with the
// OSMesa back end (llvmpipe), against baselines in tests/golden/NAME.png.
//
// Baselines change only on purpose, never in a normal run. To create or update them:
//     build/tests/engine_test --update-golden --gtest_filter='*Golden*'
// which writes each rendered view over tests/golden/NAME.png (printing how far it moved from the
// old one); look at the new images before committing them. Without the flag, a missing baseline
// is a failure that says this.
//
// Tolerance: llvmpipe gives the same bytes on every run here, so the bounds are tight. They allow
// a rounding step or two of shading (another CPU's vector width, another Mesa's LLVM) and a few
// silhouette pixels, not a change in lighting, camera or surface: a pixel is bad when a channel
// differs by more than kChannelThreshold, and a view fails when more than kAllowedBadShare of its
// pixels are bad (0.2% of 160x120 is 38 pixels).
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "app/whole_frame.h"
#include "engine/progressive_engine.h"
#include "files/image_io.h"
#include "readers/read_volume.h"
#include "tests/engine_util.h"
#include "tests/image_compare.h"
#include "tests/test_util.h"
#include "volume/phantom.h"
#include "volume/volume.h"

namespace isowall {
namespace {

constexpr int kChannelThreshold = 2;        // per RGB channel, out of 255
constexpr double kAllowedBadShare = 0.002;  // of a view's pixels

bool update_golden = false;           // set by --update-golden in main()
std::string program = "engine_test";  // argv[0], for the message naming the update command

enum class Source {
    full_surface,  // every triangle of the surface drawn at once (test::full_surface_image)
    progressive,   // the progressive engine's final image
};

struct GoldenView {
    const char* name;
    double iso;
    float yaw_deg, pitch_deg;
    Projection projection;
    Source source;
    int width_px = 160, height_px = 120;
    const char* file = nullptr;  // under ../shared/data; the phantom when none
};

std::ostream& operator<<(std::ostream& os, const GoldenView& g) {
    return os << g.name;
}

const GoldenView kViews[] = {
    {"skin_front", kPhantomSkinIso, 0, 0, Projection::perspective, Source::full_surface},
    {"bone_orbit_30_20", kPhantomBoneIso, 30, 20, Projection::perspective, Source::full_surface},
    {"skin_orthographic", kPhantomSkinIso, 0, 0, Projection::orthographic, Source::full_surface},
    // The same view as bone_orbit_30_20, so the two baselines should look alike.
    {"bone_orbit_30_20_progressive", kPhantomBoneIso, 30, 20, Projection::perspective,
     Source::progressive},
    // A head CT acquired turned about x (its sform): the front view shows the face upright, as
    // the unrotated heads' front views do (readers/, Orientation).
    {"ct_pitch_front", 60, 0, 0, Projection::perspective, Source::progressive, 160, 160,
     "formats/ct_pitch.nii.gz"},
};

// The view's volume: the phantom, or its file read as --volume reads it (nullopt when the shared
// data is absent).
std::optional<Volume> volume_of(const GoldenView& g) {
    if (!g.file) return make_phantom();
    const auto dir = test::shared_data_dir();
    if (!dir || !std::filesystem::exists(*dir / g.file)) return std::nullopt;
    return formats::read_volume((*dir / g.file).string(), std::nullopt);
}

FrameView frame_view(const Volume& volume, const GoldenView& g) {
    const float aspect = float(g.width_px) / float(g.height_px);
    FrameView fv;
    fv.width = g.width_px;
    fv.height = g.height_px;
    fv.iso = g.iso;
    const Camera front =
        front_full_view(volume.bounds(), volume.orientation().axes, aspect, g.projection);
    fv.camera = fit_depth_range(orbit(front, g.yaw_deg, g.pitch_deg), volume.bounds());
    fv.frustum = fv.camera.frustum(aspect);
    return fv;
}

Image render(const GoldenView& g, const Volume& volume) {
    auto extractor = make_surface_extractor(volume);
    auto renderer = make_renderer("osmesa");
    const FrameView fv = frame_view(volume, g);
    if (g.source == Source::full_surface)
        return test::full_surface_image(*extractor, *renderer, fv);
    ProgressiveEngine engine(*extractor);
    FrameResult frame = draw_frame(engine, fv, *renderer);
    if (!frame.completed)
        throw std::runtime_error(std::string(g.name) + ": frame did not complete");
    return std::move(frame.final_image);
}

std::filesystem::path golden_path(const GoldenView& g) {
    return std::filesystem::path(ISOWALL_SOURCE_DIR) / "tests" / "golden" /
           (std::string(g.name) + ".png");
}

class Golden : public ::testing::TestWithParam<GoldenView> {};

TEST_P(Golden, MatchesTheBaseline) {
    const GoldenView& g = GetParam();
    const std::optional<Volume> volume = volume_of(g);
    if (!volume) GTEST_SKIP() << "../shared/data/" << g.file << " absent";
    const Image rendered = render(g, *volume);
    ASSERT_EQ(rendered.width, g.width_px);
    ASSERT_EQ(rendered.height, g.height_px);
    const auto baseline_path = golden_path(g);
    const bool have_baseline = std::filesystem::exists(baseline_path);
    const test::CompareOptions options{.channel_tolerance = kChannelThreshold};
    // Where the evidence of a failure goes.
    const auto scratch = [&] { return test::scratch_dir("golden_" + std::string(g.name)); };

    if (update_golden) {
        if (have_baseline) {
            const Image old = read_image(baseline_path);
            if (old.width == rendered.width && old.height == rendered.height)
                std::cout << g.name << " against the old baseline: "
                          << test::compare_images(rendered, old, options) << "\n";
        }
        std::filesystem::create_directories(baseline_path.parent_path());
        write_image(baseline_path, rendered);
        std::cout << "wrote " << baseline_path.string() << "\n";
        return;
    }

    if (!have_baseline) {
        test::write_diff_images(scratch(), g.name, rendered, Image{});
        FAIL() << "no baseline " << baseline_path.string()
               << "; create it (then look at it) with: " << program
               << " --update-golden --gtest_filter='*Golden*'";
    }
    const Image baseline = read_image(baseline_path);
    if (baseline.width != rendered.width || baseline.height != rendered.height) {
        test::write_diff_images(scratch(), g.name, rendered, baseline, options);
        FAIL() << g.name << ": rendered " << rendered.width << "x" << rendered.height
               << ", baseline " << baseline.width << "x" << baseline.height;
    }
    const test::ImageComparison m = test::compare_images(rendered, baseline, options);
    std::cout << g.name << ": " << m.differing_pixels << " pixels differ by more than "
              << kChannelThreshold << " (" << 100.0 * m.differing_share() << "%, allowed "
              << 100.0 * kAllowedBadShare << "%), channel error max " << m.max_channel_error
              << " mean " << m.mean_channel_error << ", mask IoU " << m.mask_iou << "\n";
    if (m.differing_share() > kAllowedBadShare)
        test::write_diff_images(scratch(), g.name, rendered, baseline, options);
    EXPECT_LE(m.differing_share(), kAllowedBadShare) << g.name << ": " << m;
}

INSTANTIATE_TEST_SUITE_P(Phantom, Golden, ::testing::ValuesIn(kViews),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace isowall

// engine_test's main: gtest's own flags, plus --update-golden (see the top of this file).
int main(int argc, char** argv) {
    ::testing::InitGoogleTest(&argc, argv);
    isowall::program = argv[0];
    for (int i = 1; i < argc; ++i) {
        if (std::string_view(argv[i]) == "--update-golden") {
            isowall::update_golden = true;
        } else {
            std::cerr << argv[0] << ": error: unknown argument " << argv[i]
                      << " (expected gtest flags or --update-golden)\n";
            return 2;
        }
    }
    return RUN_ALL_TESTS();
}
