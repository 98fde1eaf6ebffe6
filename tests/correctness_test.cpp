// Correctness of an intermediate frame against the final one: final pixels and C = 1 - E.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "progressive/correctness.h"

namespace isowall {
namespace {

// A w x h frame with nothing drawn (black, depth 1).
Image background(int w, int h) {
    Image image;
    image.resize(w, h);
    return image;
}

void draw(Image& image, int x, int y, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    const std::size_t p = static_cast<std::size_t>(y) * image.width + x;
    image.rgba[p * 4 + 0] = r;
    image.rgba[p * 4 + 1] = g;
    image.rgba[p * 4 + 2] = b;
    image.rgba[p * 4 + 3] = 255;
    image.depth[p] = 0.5f;
}

// A w x h frame with every pixel drawn in one colour.
Image filled(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    Image image = background(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) draw(image, x, y, r, g, b);
    return image;
}

TEST(Correctness, EmptyFinalImageIsTriviallyMatched) {
    for (auto [w, h] : {std::pair{0, 0}, std::pair{1, 1}, std::pair{7, 3}}) {
        const Image final_image = background(w, h);
        for (const Image& intermediate : {background(w, h), filled(w, h, 10, 20, 30)}) {
            const Correctness m = measure_correctness(intermediate, final_image);
            EXPECT_EQ(m.significant, 0u) << w << "x" << h;
            EXPECT_EQ(m.final_pixels, 1.0) << w << "x" << h;
            EXPECT_EQ(m.c, 1.0) << w << "x" << h;
        }
    }
}

TEST(Correctness, IdenticalImagesAreFullyCorrect) {
    Image final_image = background(5, 4);
    draw(final_image, 0, 0, 255, 0, 0);
    draw(final_image, 4, 3, 1, 2, 3);
    draw(final_image, 2, 1, 200, 100, 50);
    const Correctness m = measure_correctness(final_image, final_image);
    EXPECT_EQ(m.significant, 3u);
    EXPECT_EQ(m.final_pixels, 1.0);
    EXPECT_EQ(m.c, 1.0);
}

TEST(Correctness, CoverageIouCountsCoveredPixelsInBothOverEither) {
    EXPECT_EQ(coverage_iou(background(3, 3), background(3, 3)), 1.0);  // neither covers a pixel
    Image a = background(4, 1), b = background(4, 1);
    draw(a, 0, 0, 1, 1, 1);
    draw(a, 1, 0, 1, 1, 1);
    draw(b, 1, 0, 9, 9, 9);  // colour is not coverage
    draw(b, 2, 0, 9, 9, 9);
    EXPECT_DOUBLE_EQ(coverage_iou(a, b), 1.0 / 3.0);
    EXPECT_DOUBLE_EQ(coverage_iou(a, a), 1.0);
    EXPECT_EQ(coverage_iou(a, background(4, 1)), 0.0);
    EXPECT_THROW(coverage_iou(a, background(2, 2)), std::invalid_argument);
}

TEST(Correctness, EmptyIntermediateIsZero) {
    const Image final_image = filled(6, 2, 90, 90, 90);
    const Correctness m = measure_correctness(background(6, 2), final_image);
    EXPECT_EQ(m.significant, 12u);
    EXPECT_EQ(m.final_pixels, 0.0);
    EXPECT_EQ(m.c, 0.0);
}

TEST(Correctness, HalfTheSignificantPixelsMissing) {
    const Image final_image = filled(4, 4, 30, 60, 90);
    Image intermediate = final_image;
    for (int x = 0; x < 4; ++x)
        for (int y = 0; y < 2; ++y) intermediate.depth[std::size_t(y) * 4 + x] = 1.0f;
    const Correctness m = measure_correctness(intermediate, final_image);
    EXPECT_EQ(m.significant, 16u);
    EXPECT_DOUBLE_EQ(m.final_pixels, 0.5);
    // E = sqrt((8 * 1^2 + 8 * 0^2) / 16)
    EXPECT_DOUBLE_EQ(m.c, 1.0 - std::sqrt(0.5));
}

TEST(Correctness, UniformColourErrorGivesOneMinusTheError) {
    const Image final_image = filled(3, 3, 128, 128, 128);
    for (int d : {2, 17, 100, 127}) {
        // The same magnitude on every channel, in both directions, so e(P) = d/255 everywhere.
        const Image intermediate =
            filled(3, 3, std::uint8_t(128 + d), std::uint8_t(128 - d), std::uint8_t(128 + d));
        const Correctness m = measure_correctness(intermediate, final_image);
        EXPECT_NEAR(m.c, 1.0 - d / 255.0, 1e-12) << "d " << d;
        EXPECT_EQ(m.final_pixels, 0.0) << "d " << d;
    }
}

TEST(Correctness, ErrorFollowsTheSection42Formula) {
    // Pixel (0,0) not drawn yet: e = 1. Pixel (1,0) off by (0.2, 0.4, 0) of full scale:
    // e^2 = (0.04 + 0.16 + 0) / 3. Pixel (2,0) exact: e = 0. E is the RMS of the three.
    Image final_image = background(3, 1);
    draw(final_image, 0, 0, 10, 10, 10);
    draw(final_image, 1, 0, 51, 102, 7);
    draw(final_image, 2, 0, 250, 0, 125);
    Image intermediate = background(3, 1);
    draw(intermediate, 1, 0, 0, 0, 7);
    draw(intermediate, 2, 0, 250, 0, 125);
    const Correctness m = measure_correctness(intermediate, final_image);
    const double expected_e = std::sqrt((1.0 + (0.04 + 0.16) / 3.0 + 0.0) / 3.0);
    EXPECT_EQ(m.significant, 3u);
    EXPECT_NEAR(m.c, 1.0 - expected_e, 1e-12);
    EXPECT_DOUBLE_EQ(m.final_pixels, 1.0 / 3.0);
}

TEST(Correctness, BackgroundDrawnOnlyInTheIntermediateDoesNotCount) {
    // A stray or since-culled triangle covers pixels the final image leaves as background.
    Image final_image = background(4, 1);
    draw(final_image, 0, 0, 40, 50, 60);
    Image intermediate = filled(4, 1, 255, 255, 255);
    draw(intermediate, 0, 0, 40, 50, 60);
    const Correctness m = measure_correctness(intermediate, final_image);
    EXPECT_EQ(m.significant, 1u);
    EXPECT_EQ(m.final_pixels, 1.0);
    EXPECT_EQ(m.c, 1.0);
}

TEST(Correctness, ToleranceDecidesFinalPixels) {
    const Image final_image = filled(2, 2, 100, 100, 100);
    const Image off_by_one = filled(2, 2, 101, 99, 100);
    const Image off_by_two = filled(2, 2, 100, 100, 102);
    EXPECT_EQ(measure_correctness(off_by_one, final_image).final_pixels, 1.0);  // default 1
    EXPECT_EQ(measure_correctness(off_by_one, final_image, 0).final_pixels, 0.0);
    EXPECT_EQ(measure_correctness(off_by_two, final_image).final_pixels, 0.0);
    EXPECT_EQ(measure_correctness(off_by_two, final_image, 2).final_pixels, 1.0);
    // C measures the error itself, whatever the tolerance.
    EXPECT_LT(measure_correctness(off_by_one, final_image).c, 1.0);
    EXPECT_EQ(measure_correctness(off_by_two, final_image, 2).c,
              measure_correctness(off_by_two, final_image, 0).c);
}

TEST(Correctness, AlphaIsIgnored) {
    const Image final_image = filled(2, 1, 10, 20, 30);
    Image intermediate = final_image;
    intermediate.rgba[3] = 0;
    const Correctness m = measure_correctness(intermediate, final_image, 0);
    EXPECT_EQ(m.final_pixels, 1.0);
    EXPECT_EQ(m.c, 1.0);
}

TEST(Correctness, SizeMismatchThrowsNamingBothSizes) {
    const Image a = background(4, 3);
    const Image b = background(3, 4);
    try {
        measure_correctness(a, b);
        FAIL() << "no exception for 4x3 against 3x4";
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("4x3"), std::string::npos) << what;
        EXPECT_NE(what.find("3x4"), std::string::npos) << what;
    }
    EXPECT_THROW(measure_correctness(background(0, 0), background(1, 1)), std::invalid_argument);
}

TEST(Correctness, PixelsDrawnBeforeADepthClearCountAsDrawn) {
    // A coarse level drew (0,0) and (1,0) in a colour near the final one; then the client cleared
    // depth to go finer, so their depth reads 1 but their colour is still on screen.
    Image final_image = background(3, 1);
    for (int x = 0; x < 3; ++x) draw(final_image, x, 0, 100, 100, 100);
    Image coarse = background(3, 1);
    draw(coarse, 0, 0, 110, 110, 110);
    draw(coarse, 1, 0, 100, 100, 100);
    std::vector<std::uint8_t> drawn;
    mark_drawn(coarse, drawn);
    EXPECT_EQ(drawn, (std::vector<std::uint8_t>{1, 1, 0}));
    Image after_clear = coarse;
    for (float& d : after_clear.depth) d = 1.0f;

    // Without the mask, both coarse pixels would count as not drawn (e = 1).
    EXPECT_NEAR(measure_correctness(after_clear, final_image).c, 0.0, 1e-12);
    const Correctness m = measure_correctness(after_clear, final_image, 1, drawn);
    // e^2: (10/255)^2 for (0,0), 0 for (1,0), 1 for (2,0) which nothing drew yet.
    const double d = 10.0 / 255.0;
    EXPECT_NEAR(m.c, 1.0 - std::sqrt((d * d + 0 + 1) / 3), 1e-12);
    EXPECT_DOUBLE_EQ(m.final_pixels, 1.0 / 3);

    // Marks accumulate: a later frame adds pixels and keeps the earlier ones.
    Image later = background(3, 1);
    draw(later, 2, 0, 1, 1, 1);
    mark_drawn(later, drawn);
    EXPECT_EQ(drawn, (std::vector<std::uint8_t>{1, 1, 1}));
    EXPECT_THROW(measure_correctness(after_clear, final_image, 1, std::vector<std::uint8_t>(2)),
                 std::invalid_argument);
}

TEST(Correctness, MalformedBuffersThrow) {
    Image short_depth = background(2, 2);
    short_depth.depth.pop_back();
    EXPECT_THROW(measure_correctness(short_depth, background(2, 2)), std::invalid_argument);
    EXPECT_THROW(measure_correctness(background(2, 2), short_depth), std::invalid_argument);
}

// The tracker follows a frame drawn a rectangle at a time (some pixels drawn again in another
// colour, some undrawn again): after every update it gives what measure_correctness gives for
// the whole frame, to the bit for the counts and within rounding for C.
TEST(CorrectnessTracker, FollowsRectangleUpdatesAsTheWholeFrameMeasureDoes) {
    std::mt19937 rng(7);
    const int w = 37, h = 23;
    Image final_image = background(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if ((x * 7 + y * 3) % 5 != 0) draw(final_image, x, y, 200, std::uint8_t(x * 6), 90);
    CorrectnessTracker tracker(final_image);
    Image shown = background(w, h);
    const Correctness empty = measure_correctness(shown, final_image);
    EXPECT_EQ(tracker.now().significant, empty.significant);
    EXPECT_EQ(tracker.now().c, 0.0);
    for (int step = 0; step < 200; ++step) {
        // Rectangles reach past the frame on every side: the tracker clips them.
        const int x0 = int(rng() % (w + 8)) - 4, y0 = int(rng() % (h + 8)) - 4;
        const PixelRect rect{x0, y0, int(rng() % 12), int(rng() % 12)};
        for (int y = std::max(rect.y, 0); y < std::min(rect.y + rect.height, h); ++y)
            for (int x = std::max(rect.x, 0); x < std::min(rect.x + rect.width, w); ++x) {
                const unsigned kind = rng() % 4;
                const std::size_t p = std::size_t(y) * w + x;
                if (kind == 0) {
                    shown.depth[p] = 1.0f;  // not drawn (any colour left there does not count)
                } else {
                    const std::size_t f = p * 4;
                    const int off = kind == 1 ? 0 : kind == 2 ? 1 : int(rng() % 60);
                    draw(shown, x, y, std::uint8_t(std::min(255, final_image.rgba[f] + off)),
                         final_image.rgba[f + 1], final_image.rgba[f + 2]);
                }
            }
        tracker.update(shown, rect);
        const Correctness want = measure_correctness(shown, final_image);
        const Correctness got = tracker.now();
        ASSERT_EQ(got.significant, want.significant) << "step " << step;
        ASSERT_EQ(got.final_pixels, want.final_pixels) << "step " << step;
        ASSERT_NEAR(got.c, want.c, 1e-12) << "step " << step;
        ASSERT_NEAR(tracker.error_squared_sum(),
                    (1.0 - want.c) * (1.0 - want.c) * double(want.significant), 1e-9);
    }
    EXPECT_GT(tracker.now().c, 0.5);
}

TEST(CorrectnessTracker, RefusesAFrameOfAnotherSizeAndAMalformedFinalImage) {
    CorrectnessTracker tracker(background(4, 3));
    EXPECT_EQ(tracker.now().c, 1.0);  // nothing significant: trivially matched
    EXPECT_THROW(tracker.update(background(3, 4), {0, 0, 3, 4}), std::invalid_argument);
    Image short_depth = background(2, 2);
    short_depth.depth.pop_back();
    EXPECT_THROW(CorrectnessTracker{short_depth}, std::invalid_argument);
}

// ---- the truth and the fidelity gate ---------------------------------------------------------

TEST(Truth, EachPixelIsTheMeanOfItsSamplesBackgroundIncluded) {
    // 4x2 samples, k = 2: the left pixel has 3 of 4 samples drawn, the right 1 of 4.
    Image big = background(4, 2);
    draw(big, 0, 0, 200, 100, 40);
    draw(big, 1, 0, 200, 100, 40);
    draw(big, 0, 1, 200, 100, 40);
    draw(big, 3, 1, 100, 100, 100);
    big.depth[0] = 0.25f;  // the nearest sample gives the pixel's depth
    const Image t = box_filtered_truth(big, 2);
    ASSERT_EQ(t.width, 2);
    ASSERT_EQ(t.height, 1);
    EXPECT_EQ(t.rgba[0], 150);  // (3 * 200 + 0) / 4
    EXPECT_EQ(t.rgba[1], 75);
    EXPECT_EQ(t.rgba[2], 30);
    EXPECT_FLOAT_EQ(t.depth[0], 0.25f);
    EXPECT_EQ(t.rgba[4], 25);  // 100 / 4: the colour counts, the coverage does not
    EXPECT_FLOAT_EQ(t.depth[1], 1.0f);
}

TEST(Truth, HalfTheSamplesCoverAPixel) {
    Image big = background(2, 2);
    draw(big, 0, 0, 255, 255, 255);
    EXPECT_FLOAT_EQ(box_filtered_truth(big, 2).depth[0], 1.0f);  // 1 of 4
    draw(big, 1, 1, 255, 255, 255);
    EXPECT_FLOAT_EQ(box_filtered_truth(big, 2).depth[0], 0.5f);  // 2 of 4
}

TEST(Truth, OneSampleIsACopyAndSidesMustDivide) {
    const Image img = filled(3, 2, 9, 8, 7);
    const Image t = box_filtered_truth(img, 1);
    EXPECT_EQ(t.rgba, img.rgba);
    EXPECT_EQ(t.depth, img.depth);
    EXPECT_THROW(box_filtered_truth(background(5, 4), 2), std::invalid_argument);
    EXPECT_THROW(box_filtered_truth(background(4, 4), 0), std::invalid_argument);
}

TEST(Fidelity, CountsTheTruthsPixelsOffByMoreThan8) {
    const Image truth = filled(4, 1, 100, 100, 100);
    Image img = truth;
    img.rgba[0] = 108;    // 8: within
    img.rgba[4] = 109;    // 9: off
    img.depth[2] = 1.0f;  // not drawn: off
    const Fidelity f = measure_fidelity(img, truth);
    EXPECT_DOUBLE_EQ(f.off_share, 0.5);
    EXPECT_DOUBLE_EQ(f.iou, 0.75);
    EXPECT_LT(f.c, 1.0);
    EXPECT_DOUBLE_EQ(measure_fidelity(truth, truth).c, 1.0);
}

TEST(Fidelity, TheGateHoldsAtItsBoundaryAndNotPastIt) {
    const Fidelity full{0.9, 0.99, 0.1};
    EXPECT_TRUE(passes_fidelity_gate(full, full));
    EXPECT_TRUE(passes_fidelity_gate({0.95, 0.999, 0}, full));  // closer than the full surface
    EXPECT_TRUE(passes_fidelity_gate({full.c - kFidelityC, full.iou - kFidelityIoU, 0}, full));
    EXPECT_FALSE(passes_fidelity_gate({full.c - kFidelityC - 1e-6, full.iou, 0}, full));
    EXPECT_FALSE(passes_fidelity_gate({full.c, full.iou - kFidelityIoU - 1e-6, 0}, full));
}

}  // namespace
}  // namespace isowall
