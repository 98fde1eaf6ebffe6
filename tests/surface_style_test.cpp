// Several surfaces' styles as an operator writes them, and the compositing of their layers: the
// text's fields and its errors, the one order every picture uses, and a blend that depends on
// depths and opacities alone, never on the order of the layers.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <stdexcept>

#include "core/image_ops.h"
#include "core/surface_style.h"

namespace isowall {
namespace {

SurfaceStyle style_of(const char* text) {
    std::string problem;
    const auto s = parse_surface_style(text, problem);
    EXPECT_TRUE(s) << text << ": " << problem;
    return s.value_or(SurfaceStyle{});
}

std::string style_problem(const char* text) {
    std::string problem;
    EXPECT_FALSE(parse_surface_style(text, problem)) << text;
    return problem;
}

TEST(SurfaceStyle, ReadsValueColourAndOpacity) {
    const SurfaceStyle plain = style_of("40");
    EXPECT_EQ(plain.iso, 40);
    EXPECT_FALSE(plain.coloured);
    EXPECT_EQ(plain.opacity, 1.0f);
    const SurfaceStyle skin = style_of("40:skin:0.3");
    EXPECT_TRUE(skin.coloured);
    EXPECT_EQ(skin.colour, glm::u8vec3(177, 122, 101));
    EXPECT_FLOAT_EQ(skin.opacity, 0.3f);
    EXPECT_EQ(style_of("1e2:#F1d691").colour, glm::u8vec3(241, 214, 145));
    const SurfaceStyle dim = style_of("-5.5::0");
    EXPECT_EQ(dim.iso, -5.5);
    EXPECT_FALSE(dim.coloured);
    EXPECT_EQ(dim.opacity, 0.0f);
    // The printed form reads back as the same style.
    for (const char* text : {"40", "40:skin:0.3", "105:#f1d691", "7::0.5", "0.25:bone:1"}) {
        const SurfaceStyle s = style_of(text);
        EXPECT_EQ(style_of(surface_style_text(s).c_str()), s) << text;
    }
}

TEST(SurfaceStyle, BadTextsSayWhy) {
    EXPECT_NE(style_problem("40:mauve").find("unknown colour 'mauve'"), std::string::npos);
    EXPECT_NE(style_problem("40:#12345g").find("#rrggbb"), std::string::npos);
    EXPECT_NE(style_problem("40:skin:1.5").find("opacity in [0, 1]"), std::string::npos);
    EXPECT_NE(style_problem("40:skin:-0.1").find("opacity in [0, 1]"), std::string::npos);
    EXPECT_NE(style_problem("40:skin:nan").find("opacity in [0, 1]"), std::string::npos);
    EXPECT_NE(style_problem("skin:40").find("isovalue"), std::string::npos);
    EXPECT_NE(style_problem("").find("isovalue"), std::string::npos);
    EXPECT_NE(style_problem("40:skin:0.3:9").find("VALUE[:COLOUR[:OPACITY]]"), std::string::npos);
}

TEST(SurfaceStyle, OneOrderAndTheSetsThatCannotBeShown) {
    const std::vector<SurfaceStyle> given{style_of("105:bone"), style_of("40:skin:0.3"),
                                          style_of("70")};
    const std::vector<SurfaceStyle> a = canonical_order(given);
    std::vector<SurfaceStyle> reversed(given.rbegin(), given.rend());
    EXPECT_EQ(canonical_order(reversed), a);
    EXPECT_EQ(a[0].iso, 40);
    EXPECT_EQ(a[2].iso, 105);
    EXPECT_EQ(surfaces_problem(given), "");
    EXPECT_NE(
        surfaces_problem({style_of("40"), style_of("40:red")}).find("isovalue 40 given twice"),
        std::string::npos);
    EXPECT_NE(surfaces_problem({}).find("no surface"), std::string::npos);
    std::vector<SurfaceStyle> many;
    for (int k = 0; k < int(kMaxSurfaces) + 1; ++k)
        many.push_back(style_of("1")), many.back().iso = k;
    EXPECT_NE(surfaces_problem(many).find("at most 8"), std::string::npos);
    EXPECT_TRUE(one_opaque_surface({style_of("40:red")}));
    EXPECT_FALSE(one_opaque_surface({style_of("40:red:0.5")}));
    EXPECT_FALSE(one_opaque_surface(given));
}

Image grey_layer(int w, int h, std::uint8_t grey, float depth) {
    Image img;
    img.resize(w, h);
    for (std::size_t p = 0; p < img.pixel_count(); ++p) {
        for (int c = 0; c < 3; ++c) img.rgba[4 * p + c] = grey;
        img.rgba[4 * p + 3] = 255;
        img.depth[p] = depth;
    }
    return img;
}

TEST(CompositeLayers, BlendsBackToFrontByDepth) {
    Image back = grey_layer(2, 1, 200, 0.6f), front = grey_layer(2, 1, 100, 0.3f);
    back.depth[1] = 1.0f;  // the second pixel: the front layer alone
    back.rgba[4] = 0;
    const Image out = composite_layers({&front, &back}, {0.5f, 1.0f});
    // 0.5 * 100 + 0.5 * 200 over the back layer; 0.5 * 100 over black where it is alone.
    EXPECT_EQ(out.rgba[0], 150);
    EXPECT_EQ(out.rgba[4], 50);
    EXPECT_EQ(out.rgba[3], 255);
    EXPECT_FLOAT_EQ(out.depth[0], 0.3f);
    // An opaque front layer hides what lies behind it; a transparent one shows nothing.
    EXPECT_EQ(composite_layers({&front, &back}, {1.0f, 1.0f}).rgba[0], 100);
    EXPECT_EQ(composite_layers({&front, &back}, {0.0f, 1.0f}).rgba[0], 200);
    // Uncovered pixels keep the first layer's background, depth 1.
    Image empty = grey_layer(2, 1, 0, 1.0f);
    const Image none = composite_layers({&empty, &empty}, {0.5f, 0.5f});
    EXPECT_EQ(none.depth[0], 1.0f);
    EXPECT_EQ(none.rgba[3], 255);
    EXPECT_THROW(composite_layers({&front}, {0.5f, 0.5f}), std::invalid_argument);
    Image small = grey_layer(1, 1, 0, 0.5f);
    EXPECT_THROW(composite_layers({&front, &small}, {0.5f, 0.5f}), std::invalid_argument);
}

// Random layers with distinct depths, composited in every order of the layers (each keeping its
// opacity): the same picture.
TEST(CompositeLayers, TheOrderOfTheLayersChangesNothing) {
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> grey(0, 255);
    std::uniform_real_distribution<float> depth(0.0f, 1.2f);
    std::vector<Image> layers;
    const std::vector<float> opacity{0.3f, 1.0f, 0.55f, 0.8f};
    for (int k = 0; k < 4; ++k) {
        Image img = grey_layer(32, 32, 0, 1.0f);
        for (std::size_t p = 0; p < img.pixel_count(); ++p) {
            for (int c = 0; c < 3; ++c) img.rgba[4 * p + c] = std::uint8_t(grey(rng));
            const float d = depth(rng);
            img.depth[p] = d >= 1.0f ? 1.0f : d;
        }
        layers.push_back(img);
    }
    std::vector<int> order(4);
    std::iota(order.begin(), order.end(), 0);
    Image first;
    int permutations = 0;
    do {
        std::vector<const Image*> l;
        std::vector<float> a;
        for (int k : order) l.push_back(&layers[k]), a.push_back(opacity[k]);
        const Image out = composite_layers(l, a);
        if (permutations++ == 0)
            first = out;
        else
            ASSERT_TRUE(out.rgba == first.rgba && out.depth == first.depth);
    } while (std::next_permutation(order.begin(), order.end()));
    EXPECT_EQ(permutations, 24);
}

}  // namespace
}  // namespace isowall
