// The wall's browser page (wall --http), its pure parts (master/wall_page.h): what a page may say,
// who steers, the JSON the pages get and the mosaic message.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "master/control_view.h"
#include "master/wall_page.h"
#include "wire/wire.h"

namespace isowall {
namespace {

using PageKind = PageMessage::Kind;

TEST(WallPage, TheFourMessagesParse) {
    EXPECT_EQ(parse_page_message(R"({"hello": "s3cret"})", "page 1").text, "s3cret");
    const PageMessage run = parse_page_message(R"({"run": "orbit -30 0"})", "page 1");
    EXPECT_EQ(run.kind, PageKind::run);
    EXPECT_EQ(run.text, "orbit -30 0");
    EXPECT_EQ(parse_page_message(R"({"snapshot": true})", "p").kind, PageKind::snapshot);
    EXPECT_EQ(parse_page_message(R"({"take": true})", "p").kind, PageKind::take);
    for (const char* line :
         {"zoom 1.25", "iso 52.2", "pan 0.1 -0.2", "quit", "look-at 0 0 5 0 0 0", "head 50 0 -20"})
        EXPECT_EQ(parse_page_message(nlohmann::json{{"run", line}}.dump(), "p").text, line);
}

// Each refusal names the page and the field, and says what was expected.
TEST(WallPage, BadMessagesAreOneLineNamingThePage) {
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"not json", "expected one of"},
        {R"([1, 2])", "expected one of"},
        {R"({"run": "orbit 1 0", "take": true})", "expected one of"},
        {R"({"fly": true})", "unknown field"},
        {R"({"run": 5})", "expected a string"},
        {R"({"hello": null})", "expected a string"},
        {R"({"take": 1})", "expected true"},
        {R"({"run": "orbit x 0"})", "orbit"},
        {R"({"run": "wait done"})", "never stalls"},
        {R"({"run": "wait time 100"})", "never stalls"},
        {R"({"run": "snapshot ../x"})", "plain name"},
        {R"({"run": "snapshot mosaic"})", "takes no name"},
        {R"({"run": "rm -rf /"})", "expected orbit"},
        {std::string(kMaxPageMessage + 1, ' '), "longer than"},
    };
    for (const auto& [bytes, want] : bad) {
        try {
            parse_page_message(bytes, "page 7");
            ADD_FAILURE() << "accepted: " << bytes.substr(0, 60);
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find("page 7"), std::string::npos) << what;
            EXPECT_NE(what.find(want), std::string::npos) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        }
    }
}

TEST(WallPage, OnePageSteersAtATimeAndAnyMayTakeOver) {
    SteeringSeat seat;
    EXPECT_FALSE(seat.holder());
    EXPECT_TRUE(seat.claim(1));  // nobody steered: page 1 takes the seat
    EXPECT_FALSE(seat.claim(2));
    EXPECT_TRUE(seat.claim(1));
    seat.take(2);
    EXPECT_EQ(seat.holder(), 2u);
    EXPECT_FALSE(seat.claim(1));
    seat.leave(1);  // not the holder: nothing changes
    EXPECT_EQ(seat.holder(), 2u);
    seat.leave(2);
    EXPECT_FALSE(seat.holder());
    EXPECT_TRUE(seat.claim(1));
}

TEST(WallPage, StateAndWelcomeAreTheFieldsThePageReads) {
    PageState s;
    s.iso = 52.2;
    s.value_min = 0;
    s.value_max = 220;
    s.frame = 3;
    s.done = true;
    s.frame_s = 1.5;
    s.figures = {40, 40, 12, 0.75, 0.82};
    s.steering = "page 2";
    s.pages = {"page 1", "page 2"};
    s.dark = {"tile 8 (rank 9 on node3): its process has ended"};
    s.clip = "x<99";
    s.dims = {200, 184, 168};
    s.surfaces = {"40:#b17a65:0.3", "105"};
    const auto j = nlohmann::json::parse(state_json(s));
    EXPECT_EQ(j["clip"], "x<99");
    EXPECT_EQ(j["surfaces"], nlohmann::json({"40:#b17a65:0.3", "105"}));
    EXPECT_EQ(j["steps"], 0);
    s.steps = 8;
    s.step = 3;
    s.playing = true;
    const auto t = nlohmann::json::parse(state_json(s));
    EXPECT_EQ(t["steps"], 8);
    EXPECT_EQ(t["step"], 3);
    EXPECT_EQ(t["playing"], true);
    EXPECT_TRUE(j["legend"].is_null());
    s.legend = {*colour_map_named("viridis"), 2, 8};
    s.legend_label = "dose.nrrd (viridis)";
    const auto k = nlohmann::json::parse(state_json(s));
    EXPECT_EQ(k["legend"]["label"], "dose.nrrd (viridis)");
    EXPECT_EQ(k["legend"]["hi"], 8);
    ASSERT_EQ(k["legend"]["stops"].size(), 9u);
    EXPECT_EQ(k["legend"]["stops"][0], "#440154");
    EXPECT_EQ(k["legend"]["stops"][8], "#fde725");
    EXPECT_EQ(j["dims"], nlohmann::json({200, 184, 168}));
    ASSERT_EQ(j["dark"].size(), 1u);
    EXPECT_EQ(j["dark"][0], "tile 8 (rank 9 on node3): its process has ended");
    EXPECT_EQ(j["type"], "state");
    EXPECT_EQ(j["iso"], 52.2);
    EXPECT_EQ(j["frame"], 3);
    EXPECT_EQ(j["done"], true);
    EXPECT_EQ(j["jobs"], 40);
    EXPECT_EQ(j["migrated"], 12);
    EXPECT_EQ(j["emulated_s"], 0.75);
    EXPECT_EQ(j["balance"], 0.82);
    EXPECT_EQ(j["c99_s"], -1);  // not measured
    EXPECT_EQ(j["steering"], "page 2");
    EXPECT_EQ(j["pages"].size(), 2u);

    ControlLayout layout;
    layout.mosaic = {200, 100};
    layout.tiles = {{0, 0, 99, 100}, {101, 0, 99, 100}};
    const auto w = nlohmann::json::parse(welcome_json("page 1", layout, "walls/2x1.toml"));
    EXPECT_EQ(w["you"], "page 1");
    EXPECT_EQ(w["width"], 200);
    EXPECT_EQ(w["tiles"][1][0], 101);
    // Bytes that are not UTF-8 (a hostile line echoed back) still give valid JSON.
    const auto r = nlohmann::json::parse(ran_json("page 1", "orbit \xff 0", "bad \xfe"));
    EXPECT_EQ(r["type"], "ran");
    EXPECT_EQ(nlohmann::json::parse(error_json("x"))["text"], "x");
}

TEST(WallPage, TheMosaicRoundTripsAndMalformedOnesThrow) {
    ControlLayout layout;
    layout.mosaic = {64, 24};
    layout.tiles = {{0, 0, 31, 24}, {33, 0, 31, 24}};
    Image preview;
    preview.width = 4;
    preview.height = 3;
    preview.rgba.assign(4 * 3 * 4, 0);
    for (std::size_t i = 0; i < preview.rgba.size(); ++i)
        preview.rgba[i] = static_cast<std::uint8_t>(i * 7);
    const Image mosaic = compose_mosaic(layout, {preview, {}});
    ASSERT_EQ(mosaic.width, 64);
    ASSERT_EQ(mosaic.height, 24);
    const std::string bytes = encode_mosaic(mosaic, 42);
    std::uint64_t frame = 0;
    const Image back = decode_mosaic(bytes, &frame);
    EXPECT_EQ(frame, 42u);
    ASSERT_EQ(back.width, mosaic.width);
    for (std::size_t i = 0; i < mosaic.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c)
            ASSERT_EQ(back.rgba[i * 4 + c], mosaic.rgba[i * 4 + c]) << "pixel " << i;
    // The control window's picture is this mosaic with the status bar under it.
    const Image window = compose_control(layout, {preview, {}}, {"a", "b"});
    EXPECT_TRUE(std::equal(mosaic.rgba.begin(), mosaic.rgba.end(), window.rgba.begin()));
    // The page's unit test (web/test/wall_page.test.mjs) decodes this mosaic from a file; that
    // file decodes here to the same picture (ISOWALL_WRITE_MOSAIC=1 writes it anew).
    const auto file = std::filesystem::path(ISOWALL_SOURCE_DIR) / "web/test/data/mosaic_64x24.bin";
    if (std::getenv("ISOWALL_WRITE_MOSAIC")) std::ofstream(file, std::ios::binary) << bytes;
    std::ifstream in(file, std::ios::binary);
    const std::string committed((std::istreambuf_iterator<char>(in)), {});
    EXPECT_EQ(decode_mosaic(committed).rgba, back.rgba);
    for (std::size_t cut = 0; cut < bytes.size(); ++cut)
        EXPECT_THROW(decode_mosaic(bytes.substr(0, cut)), WireError) << cut;
    std::string huge = bytes;
    huge[4] = huge[5] = huge[6] = static_cast<char>(0x7F);
    EXPECT_THROW(decode_mosaic(huge), WireError);
}

}  // namespace
}  // namespace isowall
