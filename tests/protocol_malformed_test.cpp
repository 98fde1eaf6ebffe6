// The typed wire protocol, malformed input of every kind (truncated, another version, trailing
// bytes, huge counts, bad bools, enums and sizes, unknown tags, random mutations) throws WireError
// naming the message and the field; it never crashes nor allocates more than the message holds.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <new>
#include <random>

#include "tests/largest_allocation.h"
#include "tests/protocol_test_util.h"
#include "volume/time_steps.h"

namespace isowall {
namespace {

using test::largest_allocation_in;

using namespace protocol_testing;

// ---- malformed input common to every message -------------------------------------------------

TEST(ProtocolMalformed, EveryTruncationThrows) {
    for (const Sample& s : samples()) {
        for (std::size_t n = 0; n < s.bytes.size(); ++n)
            EXPECT_THROW(decode_message(s.tag, std::span(s.bytes).first(n)), WireError)
                << s.name << " cut to " << n << " of " << s.bytes.size() << " bytes";
    }
}

TEST(ProtocolMalformed, AnotherVersionThrows) {
    for (const Sample& s : samples()) {
        for (int delta : {-1, 1, 255}) {
            Bytes bytes = s.bytes;
            bytes[0] = static_cast<std::byte>(static_cast<int>(bytes[0]) + delta);
            expect_wire_error(s.tag, bytes, "version");
        }
    }
}

TEST(ProtocolMalformed, TrailingByteThrows) {
    for (const Sample& s : samples()) {
        Bytes bytes = s.bytes;
        bytes.push_back(std::byte{0});
        expect_wire_error(s.tag, bytes, "trailing");
    }
}

TEST(ProtocolMalformed, UnknownTagThrows) {
    const Bytes bytes = encode(QuitMsg{});
    for (std::int32_t tag : {0, 12, 15, 20, 31, -1, std::numeric_limits<std::int32_t>::max()})
        EXPECT_THROW(decode_message(static_cast<Tag>(tag), bytes), WireError) << "tag " << tag;
}

TEST(ProtocolMalformed, DecodeAsAnotherTypeThrows) {
    const Bytes bytes = encode(sample_image());
    try {
        decode_as<ViewMsg>(Tag::image, bytes);
        ADD_FAILURE() << "an image decoded as a view";
    } catch (const WireError& e) {
        EXPECT_STREQ(e.what(), "expected a view message, got image");
    }
    EXPECT_THROW(decode_as<TileHelloMsg>(Tag::quit, encode(QuitMsg{})), WireError);
    EXPECT_EQ(decode_as<ImageMsg>(Tag::image, bytes), sample_image());
}

// ---- hello ----------------------------------------------------------------------------------

TEST(ProtocolMalformed, AllocationsAreSeen) {
    // The measure the "without allocating" tests rely on: a real 64x64 image's pixels show up.
    ImageMsg m;
    m.width = m.height = 64;
    m.rgba.assign(64 * 64 * 4, 0x40);
    const Bytes bytes = encode(m);
    EXPECT_GE(largest_allocation_in([&] { EXPECT_EQ(decode_as<ImageMsg>(Tag::image, bytes), m); }),
              m.rgba.size());
}

TEST(ProtocolMalformed, HelloWithAHugeLengthThrowsWithoutAllocating) {
    for (std::uint64_t length :
         {kHugeCount, std::numeric_limits<std::uint64_t>::max(), std::uint64_t{5}}) {
        MessageWriter w(TileHelloMsg::kVersion);
        w.put(length);
        w.put(std::uint32_t{0x74736f68});  // 4 bytes of a host name, fewer than the length
        const Bytes bytes = w.take();
        const auto largest =
            largest_allocation_in([&] { expect_wire_error(Tag::hello, bytes, "length"); });
        EXPECT_LT(largest, 4096u) << "length " << length;
    }
}

TEST(ProtocolMalformed, HelloWithNoThreadsOrTooManyThrows) {
    for (const std::uint32_t threads : {0u, 1025u}) {
        TileHelloMsg h = sample_hello();
        h.threads = threads;
        expect_wire_error(Tag::hello, encode(h), "threads: expected 1 to 1024");
    }
}

TEST(ProtocolMalformed, HelloWithABadBoolThrows) {
    Bytes bytes = encode(sample_hello());
    bytes.back() = std::byte{2};  // `loaded` is the last byte
    expect_wire_error(Tag::hello, bytes, "bool byte 2");
}

// ---- view ---------------------------------------------------------------------------------------

struct ViewFault {
    const char* field;  // what the error must name
    void (*apply)(ViewMsg&);
};

TEST(ProtocolMalformed, ViewFaultsThrowNamingTheField) {
    const ViewFault faults[] = {
        {"camera.eye", [](ViewMsg& m) { m.view.camera.eye.y = kNaN; }},
        {"camera.target", [](ViewMsg& m) { m.view.camera.target.z = -kInf; }},
        {"camera.up", [](ViewMsg& m) { m.view.camera.up.x = kInf; }},
        {"camera.projection", [](ViewMsg& m) { m.view.camera.projection = Projection{2}; }},
        {"camera.projection", [](ViewMsg& m) { m.view.camera.projection = Projection{-1}; }},
        {"camera.fovy_deg", [](ViewMsg& m) { m.view.camera.fovy_deg = kNaN; }},
        {"camera.ortho_height", [](ViewMsg& m) { m.view.camera.ortho_height = kInf; }},
        {"camera.near_z", [](ViewMsg& m) { m.view.camera.near_z = kNaN; }},
        {"camera.far_z", [](ViewMsg& m) { m.view.camera.far_z = kInf; }},
        {"frustum.left", [](ViewMsg& m) { m.view.frustum.left = kNaN; }},
        {"frustum.right", [](ViewMsg& m) { m.view.frustum.right = kInf; }},
        {"frustum.bottom", [](ViewMsg& m) { m.view.frustum.bottom = -kInf; }},
        {"frustum.top", [](ViewMsg& m) { m.view.frustum.top = kNaN; }},
        {"frustum.near_z", [](ViewMsg& m) { m.view.frustum.near_z = kNaN; }},
        {"frustum.far_z", [](ViewMsg& m) { m.view.frustum.far_z = kInf; }},
        {"frustum.projection", [](ViewMsg& m) { m.view.frustum.projection = Projection{7}; }},
        {"view.width", [](ViewMsg& m) { m.view.width = 0; }},
        {"view.width", [](ViewMsg& m) { m.view.width = -1920; }},
        {"view.width", [](ViewMsg& m) { m.view.width = kMaxImageSide + 1; }},
        {"view.height", [](ViewMsg& m) { m.view.height = 0; }},
        {"view.height", [](ViewMsg& m) { m.view.height = kMaxImageSide + 1; }},
        {"view.iso", [](ViewMsg& m) { m.view.iso = std::numeric_limits<double>::quiet_NaN(); }},
        {"view.iso", [](ViewMsg& m) { m.view.iso = -std::numeric_limits<double>::infinity(); }},
        {"view.clip.normal",
         [](ViewMsg& m) {
             m.view.clip.planes[0].normal = {2, 0, 0};
         }},
        {"view.clip.normal", [](ViewMsg& m) { m.view.clip.planes[1].normal.x = kNaN; }},
        {"view.clip.at", [](ViewMsg& m) { m.view.clip.planes[1].at = kInf; }},
        {"view.surfaces.iso", [](ViewMsg& m) { m.surfaces[1].iso = kNaN; }},
        {"view.surfaces.opacity", [](ViewMsg& m) { m.surfaces[0].opacity = 1.5f; }},
        {"view.surfaces.opacity", [](ViewMsg& m) { m.surfaces[0].opacity = -kInf; }},
    };
    for (const ViewFault& f : faults) {
        ViewMsg m = sample_view();
        f.apply(m);
        SCOPED_TRACE(testing::Message() << f.field << " in " << testing::PrintToString(m));
        expect_wire_error(Tag::view, encode(m), f.field);
    }
    // More planes, or surfaces, than any view has: the planes' count byte follows the isovalue,
    // the surfaces' count the planes.
    // (The step's 4 bytes come last.)
    ViewMsg none = sample_view();
    none.view.clip = {};
    none.surfaces = {};
    none.step = 0;
    Bytes bytes = encode(none);
    const std::size_t at = bytes.size() - 5;  // the surfaces' count (the step's 4 bytes after it)
    ASSERT_EQ(bytes[at - 1], std::byte{0});
    ASSERT_EQ(bytes[at], std::byte{0});
    bytes[at] = std::byte{kMaxSurfaces + 1};
    expect_wire_error(Tag::view, bytes, "view.surfaces: expected at most 8 surfaces, got 9");
    bytes[at] = std::byte{0};
    bytes[at - 1] = std::byte{kMaxClipPlanes + 1};
    expect_wire_error(Tag::view, bytes, "view.clip: expected at most 8 planes, got 9");
    // A coloured flag is a bool byte: 0 or 1.
    ViewMsg one = sample_view();
    one.view.clip = {};
    one.surfaces.resize(1);
    one.step = 0;
    bytes = encode(one);
    bytes[bytes.size() - 5] = std::byte{2};
    expect_wire_error(Tag::view, bytes, "bool byte 2");
    // A step past any series.
    one.step = kMaxTimeSteps;
    expect_wire_error(Tag::view, encode(one), "step: expected below 100000");
}

// ---- image --------------------------------------------------------------------------------------

struct ImageFault {
    const char* field;
    void (*apply)(ImageMsg&);
};

TEST(ProtocolMalformed, ImageFaultsThrowNamingTheField) {
    const ImageFault faults[] = {
        {"width", [](ImageMsg& m) { m.width = -1; }},
        {"width", [](ImageMsg& m) { m.width = kMaxImageSide + 1; }},
        {"height", [](ImageMsg& m) { m.height = -3; }},
        {"height", [](ImageMsg& m) { m.height = std::numeric_limits<std::int32_t>::max(); }},
        {"rgba", [](ImageMsg& m) { m.rgba.pop_back(); }},
        {"rgba", [](ImageMsg& m) { m.rgba.push_back(0); }},
        {"rgba", [](ImageMsg& m) { m.rgba.clear(); }},
        {"rgba", [](ImageMsg& m) { m.width = 2; }},  // sizes no longer match the pixels
        {"depth", [](ImageMsg& m) { m.depth.pop_back(); }},
        {"depth", [](ImageMsg& m) { m.depth.push_back(1.0f); }},
        {"depth", [](ImageMsg& m) { m.depth.resize(m.rgba.size()); }},  // a count of bytes
    };
    for (const ImageFault& f : faults) {
        ImageMsg m = sample_image();
        f.apply(m);
        SCOPED_TRACE(testing::Message() << f.field << " in " << testing::PrintToString(m));
        expect_wire_error(Tag::image, encode(m), f.field);
    }
}

// The image layout, written by hand so a count can lie: generation, width, height, then the
// rgba length and bytes, then the depth count and floats.
Bytes image_bytes(std::int32_t width, std::int32_t height, std::uint64_t rgba_count,
                  std::size_t rgba_bytes_present, std::uint64_t depth_count) {
    MessageWriter w(ImageMsg::kVersion);
    w.put(std::uint64_t{1});
    w.put(width);
    w.put(height);
    w.put(rgba_count);
    for (std::size_t i = 0; i < rgba_bytes_present; ++i) w.put(std::uint8_t{0x7f});
    w.put(depth_count);
    w.put(1.0f);  // one float present, whatever the count says
    return w.take();
}

TEST(ProtocolMalformed, ImageWithAHugeCountThrowsWithoutAllocating) {
    struct Case {
        const char* field;
        Bytes bytes;
    };
    const std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
    const Case cases[] = {
        {"length", image_bytes(1, 1, kHugeCount, 4, 0)},
        {"length", image_bytes(1, 1, kMax, 4, 0)},
        // a count that fits a 32768x32768 image but not the message
        {"length", image_bytes(kMaxImageSide, kMaxImageSide, 4ull << 30, 4, 0)},
        {"array", image_bytes(1, 1, 4, 4, kHugeCount)},
        {"array", image_bytes(1, 1, 4, 4, kMax)},
        {"array", image_bytes(1, 1, 4, 4, kMax / 4 + 1)},  // count * 4 wraps to a small number
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(hex(c.bytes));
        const auto largest =
            largest_allocation_in([&] { expect_wire_error(Tag::image, c.bytes, c.field); });
        EXPECT_LT(largest, 4096u);
    }
}

// ---- preview ------------------------------------------------------------------------------------

struct PreviewFault {
    const char* field;
    void (*apply)(PreviewMsg&);
};

TEST(ProtocolMalformed, PreviewFaultsThrowNamingTheField) {
    const PreviewFault faults[] = {
        {"width", [](PreviewMsg& m) { m.width = 0; }},  // the window divides by the size
        {"width", [](PreviewMsg& m) { m.width = -1; }},
        {"width", [](PreviewMsg& m) { m.width = kMaxPreviewSide + 1; }},
        {"height", [](PreviewMsg& m) { m.height = 0; }},
        {"height", [](PreviewMsg& m) { m.height = std::numeric_limits<std::int32_t>::max(); }},
        {"rgb", [](PreviewMsg& m) { m.rgb.pop_back(); }},
        {"rgb", [](PreviewMsg& m) { m.rgb.push_back(0); }},
        {"rgb", [](PreviewMsg& m) { m.rgb.clear(); }},
        {"rgb", [](PreviewMsg& m) { m.rgb.resize(3 * 2 * 4); }},  // RGBA, not RGB
        {"rgb", [](PreviewMsg& m) { m.width = 2; }},              // sizes no longer match
    };
    for (const PreviewFault& f : faults) {
        PreviewMsg m = sample_preview();
        f.apply(m);
        SCOPED_TRACE(testing::Message() << f.field << " in " << testing::PrintToString(m));
        expect_wire_error(Tag::preview, encode(m), f.field);
    }
}

TEST(ProtocolMalformed, PreviewWithAHugeLengthThrowsWithoutAllocating) {
    for (std::uint64_t length : {kHugeCount, std::numeric_limits<std::uint64_t>::max(),
                                 std::uint64_t{kMaxPreviewSide} * kMaxPreviewSide * 3}) {
        MessageWriter w(PreviewMsg::kVersion);
        w.put(std::uint64_t{1});
        w.put(std::int32_t{kMaxPreviewSide});
        w.put(std::int32_t{kMaxPreviewSide});
        w.put(length);
        w.put(std::uint32_t{0});  // 4 bytes of pixels, far fewer than the length
        const Bytes bytes = w.take();
        const auto largest =
            largest_allocation_in([&] { expect_wire_error(Tag::preview, bytes, "length"); });
        EXPECT_LT(largest, 4096u) << "length " << length;
    }
}

// ---- tile result --------------------------------------------------------------------------------

TEST(ProtocolMalformed, FailedFaultsThrowNamingTheField) {
    Bytes bad_bool = encode(FailedMsg{true, "x"});
    bad_bool[1] = std::byte{2};  // after the version byte
    expect_wire_error(Tag::failed, bad_bool, "input");
    // A what longer than the limit (the encoder cuts; a forged message is refused).
    MessageWriter w(FailedMsg::kVersion);
    w.put(std::uint8_t{0});
    w.put_string(std::string(kMaxFailedBytes + 1, 'x'));
    expect_wire_error(Tag::failed, w.take(), "what");
    // The encoder cuts an over-long line to the limit instead of sending what would be refused.
    const Bytes cut = encode(FailedMsg{false, std::string(kMaxFailedBytes + 100, 'y')});
    EXPECT_EQ(decode_as<FailedMsg>(Tag::failed, cut).what.size(), kMaxFailedBytes);
}

TEST(ProtocolMalformed, TileResultWithABadStageThrows) {
    for (std::uint8_t stage :
         {static_cast<std::uint8_t>(std::size(kTraceStages)), std::uint8_t{255}}) {
        TileResultMsg m = sample_tile_result();
        m.spans[1].stage = stage;
        SCOPED_TRACE(testing::Message() << "stage " << int{stage});
        expect_wire_error(Tag::tile_result, encode(m), "spans.stage");
    }
}

TEST(ProtocolMalformed, TileResultWithAHugeSpanCountThrowsWithoutAllocating) {
    // One span is 25 bytes on the wire: a count of 2 with 49 bytes left must fail too.
    for (std::uint64_t count :
         {kHugeCount, std::numeric_limits<std::uint64_t>::max(), std::uint64_t{2}}) {
        TileResultMsg m = sample_tile_result();
        m.spans.clear();
        Bytes bytes = encode(m);
        // Replace the span count, the last 8 bytes of a message with no spans.
        MessageWriter tail(0);
        tail.put(count);
        for (int i = 0; i < 49; ++i) tail.put(std::uint8_t{0});
        ASSERT_GE(bytes.size(), 8u);
        bytes.erase(bytes.end() - 8, bytes.end());
        bytes.insert(bytes.end(), tail.bytes().begin() + 1, tail.bytes().end());
        SCOPED_TRACE(testing::Message() << "count " << count);
        const auto largest =
            largest_allocation_in([&] { expect_wire_error(Tag::tile_result, bytes, "count"); });
        EXPECT_LT(largest, 4096u);
    }
}

// ---- mutation fuzz ------------------------------------------------------------------------------

// Counts are where a decoder allocates, so a mutation sometimes writes one of these over 8 bytes.
constexpr std::uint64_t kInterestingWords[] = {0,
                                               1,
                                               4,
                                               25,
                                               std::uint64_t{1} << 31,
                                               std::uint64_t{1} << 32,
                                               kHugeCount,
                                               std::numeric_limits<std::uint64_t>::max()};

// One random change: a bit flip, a byte set, a cut, an inserted byte, an 8-byte word or the tag.
std::string mutate(Bytes& b, Tag& tag, std::mt19937_64& rng) {
    switch (rng() % 6) {
        case 0:
            if (b.empty()) return "flip (empty)";
            {
                const std::size_t at = rng() % b.size();
                b[at] ^= static_cast<std::byte>(1u << (rng() % 8));
                return "flip at " + std::to_string(at);
            }
        case 1:
            if (b.empty()) return "set (empty)";
            {
                const std::size_t at = rng() % b.size();
                b[at] = static_cast<std::byte>(rng() & 0xff);
                return "set at " + std::to_string(at);
            }
        case 2: {
            b.resize(rng() % (b.size() + 1));
            return "cut to " + std::to_string(b.size());
        }
        case 3: {
            const std::size_t at = rng() % (b.size() + 1);
            b.insert(b.begin() + static_cast<std::ptrdiff_t>(at),
                     static_cast<std::byte>(rng() & 0xff));
            return "insert at " + std::to_string(at);
        }
        case 4: {
            if (b.size() < 8) return "word (short)";
            const std::size_t at = rng() % (b.size() - 7);
            std::uint64_t word = kInterestingWords[rng() % std::size(kInterestingWords)];
            for (std::size_t i = 0; i < 8; ++i, word >>= 8)
                b[at + i] = static_cast<std::byte>(word & 0xff);
            return "word at " + std::to_string(at);
        }
        default: {
            // 1..12: every frame tag and one unknown one
            tag = static_cast<Tag>(1 + rng() % 12);
            return "tag " + std::to_string(static_cast<int>(tag));
        }
    }
}

TEST(ProtocolFuzz, MutatedMessagesDecodeOrThrowWireError) {
    constexpr int kIterations = 20000;
    std::mt19937_64 rng(0x15011a11);  // fixed: a failure names its iteration and replays
    const std::vector<Sample> base = samples();
    int decoded = 0, rejected = 0;
    for (int i = 0; i < kIterations; ++i) {
        const Sample& s = base[rng() % base.size()];
        Tag tag = s.tag;
        Bytes bytes = s.bytes;
        std::string what = s.name;
        const int mutations = 1 + static_cast<int>(rng() % 3);
        for (int k = 0; k < mutations; ++k) what += ", " + mutate(bytes, tag, rng);
        try {
            const Message m = decode_message(tag, bytes);
            ++decoded;
            // Decoding is canonical: whatever decodes encodes back to the very same bytes.
            EXPECT_EQ(tag_of(m), tag) << "iteration " << i << ": " << what;
            EXPECT_EQ(hex(encode(m)), hex(bytes)) << "iteration " << i << ": " << what;
        } catch (const WireError&) {
            ++rejected;
        } catch (const std::exception& e) {
            ADD_FAILURE() << "iteration " << i << " (" << what << "): not a WireError: " << e.what()
                          << "; bytes: " << hex(bytes);
        }
    }
    // Both outcomes must occur, or the mutations are too timid or too wild to test anything.
    EXPECT_GT(decoded, kIterations / 20);
    EXPECT_GT(rejected, kIterations / 20);
    std::printf("fuzz: %d decoded, %d rejected\n", decoded, rejected);
}

}  // namespace
}  // namespace isowall
