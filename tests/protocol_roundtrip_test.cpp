// The typed wire protocol, well-formed input: every message round-trips with every field set (and
// with degenerate and limit values), and the byte format itself is pinned: little-endian, the
// version first, a fixed-size view, the tag names.
#include <gtest/gtest.h>

#include <string>
#include <variant>

#include "tests/protocol_test_util.h"

namespace isowall {
namespace {

using namespace protocol_testing;

// ---- degenerate messages first ---------------------------------------------------------------

TEST(Protocol, DegenerateMessagesRoundTrip) {
    expect_round_trip(TileHelloMsg{});  // empty host
    expect_round_trip(SnapshotMsg{});
    expect_round_trip(QuitMsg{});
    expect_round_trip(ImageMsg{});       // 0x0, no pixels, no depth
    expect_round_trip(ProgressMsg{});    // all zero
    expect_round_trip(TileResultMsg{});  // no spans
    ImageMsg no_rows;
    no_rows.width = kMaxImageSide;  // the largest side with no pixels at all
    expect_round_trip(no_rows);

    ViewMsg one_pixel = sample_view();
    one_pixel.view.width = 1;
    one_pixel.view.height = 1;
    expect_round_trip(one_pixel);
    expect_round_trip(ReleaseMsg{});
    expect_round_trip(StartMsg{});
    expect_round_trip(AliveMsg{});
    expect_round_trip(PreviewMsg{});  // one black pixel
    expect_round_trip(JobDoneMsg{});
    expect_round_trip(LandedMsg{});
    expect_round_trip(CurveAskMsg{});
    expect_round_trip(LostMsg{7});
}

TEST(Protocol, ViewAtTheLimitsRoundTrips) {
    ViewMsg m = sample_view();
    m.view.width = kMaxImageSide;
    m.view.height = kMaxImageSide;
    expect_round_trip(m);
    std::string problem;
    m.view.clip = clip_box({0, 0, 0}, {1, 1, 1}, problem).value();  // the most planes
    m.view.clip.add({{1, 0, 0}, 0.5f});
    m.view.clip.add({{0, 1, 0}, 0.5f});
    ASSERT_EQ(m.view.clip.count, kMaxClipPlanes);
    expect_round_trip(m);
    m.view.clip = {};  // none
    expect_round_trip(m);
}

// ---- every message with every field set ------------------------------------------------------

TEST(Protocol, HelloRoundTrips) {
    expect_round_trip(sample_hello());
}
TEST(Protocol, ViewRoundTrips) {
    expect_round_trip(sample_view());
}
TEST(Protocol, ProgressRoundTrips) {
    expect_round_trip(sample_progress());
}
TEST(Protocol, SnapshotRoundTrips) {
    expect_round_trip(SnapshotMsg{});
}
TEST(Protocol, ImageRoundTrips) {
    expect_round_trip(sample_image());
}
TEST(Protocol, ImageWithoutDepthRoundTrips) {
    ImageMsg m = sample_image();
    m.depth.clear();
    expect_round_trip(m);
}
TEST(Protocol, QuitRoundTrips) {
    expect_round_trip(QuitMsg{});
}
TEST(Protocol, TileResultRoundTrips) {
    expect_round_trip(sample_tile_result());
}
TEST(Protocol, PreviewRoundTrips) {
    expect_round_trip(sample_preview());
}
TEST(Protocol, PreviewAtTheLimitsRoundTrips) {
    PreviewMsg m;
    m.width = kMaxPreviewSide;
    m.height = 1;
    m.rgb.assign(std::size_t{kMaxPreviewSide} * 3, 0xab);
    expect_round_trip(m);
    std::swap(m.width, m.height);
    expect_round_trip(m);
}
TEST(Protocol, JobRoundTrips) {
    expect_round_trip(sample_job());
    JobMsg coarse = sample_job();
    coarse.band = Band::coarse;
    coarse.rect = {1600, 840, 320, 240};  // touches the right and bottom edges
    expect_round_trip(coarse);
}
TEST(Protocol, JobDoneRoundTrips) {
    expect_round_trip(sample_job_done());
}
TEST(Protocol, RegionRoundTrips) {
    expect_round_trip(sample_region());
}
TEST(Protocol, LandedRoundTrips) {
    expect_round_trip(LandedMsg{0xfedcba9876543210ULL, 0xffffffffu});
}
TEST(Protocol, CurveAskAndCurveRoundTrip) {
    expect_round_trip(CurveAskMsg{0xfedcba9876543210ULL});
    expect_round_trip(CurveMsg{});
    expect_round_trip(CurveMsg{{7, 123456, {{0.25, 100, 1.5}, {0.5, 123456, 0}}}});
}

TEST(Protocol, FailedRoundTrips) {
    expect_round_trip(FailedMsg{});
    expect_round_trip(FailedMsg{true, "volume.nrrd: sizes: expected 3 numbers"});
    expect_round_trip(FailedMsg{false, std::string(kMaxFailedBytes, 'x')});
}

TEST(Protocol, PerspectiveProjectionRoundTrips) {
    ViewMsg m = sample_view();
    m.view.camera.projection = Projection::perspective;
    m.view.frustum.projection = Projection::perspective;
    expect_round_trip(m);
}

// ---- the byte format itself -------------------------------------------------------------------

TEST(Protocol, ProgressBytesAreLittleEndianWithTheVersionFirst) {
    const Bytes bytes = encode(ProgressMsg{0x0102030405060708ULL, 9, 1.5});
    const std::string expected =
        "03 "                        // version
        "08 07 06 05 04 03 02 01 "   // generation, low byte first
        "09 00 00 00 00 00 00 00 "   // rays
        "00 00 00 00 00 00 f8 3f ";  // cpu_s: 1.5 is 0x3ff8000000000000
    EXPECT_EQ(hex(bytes), expected);
}

TEST(Protocol, ViewHasAFixedSize) {
    // version 1 + generation 8 + camera (3 vec3 36, projection 4, 4 floats 16) 56 + frustum
    // (6 floats 24, projection 4) 28 + width, height 8 + iso 8 + clip (count 1, two planes of a
    // vec3 and a float, 16 each) 33 + surfaces (count 1, two of iso 8, colour 3, opacity 4 and a
    // flag 1) 33 + step 4: a change here is a change of the wire format and needs a new
    // ViewMsg::kVersion.
    EXPECT_EQ(encode(sample_view()).size(), 1u + 8 + 56 + 28 + 8 + 8 + 33 + 33 + 4);
}

TEST(Protocol, TagNames) {
    EXPECT_STREQ(to_string(Tag::hello), "hello");
    EXPECT_STREQ(to_string(Tag::view), "view");
    EXPECT_STREQ(to_string(Tag::progress), "progress");
    EXPECT_STREQ(to_string(Tag::snapshot), "snapshot");
    EXPECT_STREQ(to_string(Tag::image), "image");
    EXPECT_STREQ(to_string(Tag::quit), "quit");
    EXPECT_STREQ(to_string(Tag::tile_result), "tile_result");
    EXPECT_STREQ(to_string(Tag::release), "release");
    EXPECT_STREQ(to_string(Tag::start), "start");
    EXPECT_STREQ(to_string(Tag::alive), "alive");
    EXPECT_STREQ(to_string(Tag::preview), "preview");
    EXPECT_STREQ(to_string(Tag::job), "job");
    EXPECT_STREQ(to_string(Tag::job_done), "job_done");
    EXPECT_STREQ(to_string(Tag::region), "region");
    EXPECT_STREQ(to_string(Tag::landed), "landed");
    EXPECT_STREQ(to_string(Tag::lost), "lost");
    EXPECT_STREQ(to_string(static_cast<Tag>(0)), "unknown");
    EXPECT_STREQ(to_string(Tag::store_ask), "store_ask");
    EXPECT_STREQ(to_string(Tag::store_meta), "store_meta");
    EXPECT_STREQ(to_string(Tag::store_part), "store_part");
    EXPECT_STREQ(to_string(static_cast<Tag>(15)), "unknown");
    EXPECT_STREQ(to_string(Tag::curve_ask), "curve_ask");
    EXPECT_STREQ(to_string(Tag::curve), "curve");
    EXPECT_STREQ(to_string(Tag::failed), "failed");
    EXPECT_STREQ(to_string(static_cast<Tag>(24)), "unknown");
    EXPECT_STREQ(to_string(static_cast<Tag>(-1)), "unknown");
}

}  // namespace
}  // namespace isowall
