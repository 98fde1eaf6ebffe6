// The remote-viewing protocol (remote/view_protocol.h, remote/view_framing.h): every message
// round-trips with every field set; every truncation throws; a bad magic, version, type or length
// and trailing bytes each give their own error; the FrameParser rebuilds messages from chunks of
// any size, one byte included.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "tests/remote_protocol_test_util.h"

namespace isowall::remote {
namespace {

using namespace remote_testing;
using Bytes = std::vector<std::byte>;

// The error `f` throws, or a failure naming `expected`.
template <class F>
std::string wire_error_of(F f, const std::string& expected) {
    try {
        f();
    } catch (const WireError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no WireError, expected one naming " << expected;
    return {};
}

Bytes stream_of(const std::vector<RemoteMessage>& messages) {
    Bytes out;
    for (const RemoteMessage& m : messages) {
        const Bytes f = encode_frame(m);
        out.insert(out.end(), f.begin(), f.end());
    }
    return out;
}

TEST(RemoteProtocol, EveryMessageRoundTrips) {
    const auto all = samples();
    ASSERT_EQ(all.size(), std::size_t{kLastRemoteTag}) << "a sample of every type";
    for (const RemoteMessage& m : all) {
        SCOPED_TRACE(to_string(type_of(m)));
        EXPECT_EQ(decode_frame(encode_frame(m)), m);
        EXPECT_EQ(decode_payload(type_of(m), encode_payload(m)), m);
    }
}

TEST(RemoteProtocol, SamplesDifferFromDefaults) {
    // A round trip proves a field travels only when the sample sets it to something else.
    for (const RemoteMessage& m : samples()) {
        if (type_of(m) == RemoteTag::bye) continue;
        const RemoteMessage blank = std::visit(
            [](const auto& msg) -> RemoteMessage { return std::decay_t<decltype(msg)>{}; }, m);
        EXPECT_NE(encode_payload(m), encode_payload(blank)) << to_string(type_of(m));
    }
}

TEST(RemoteProtocol, HeaderBytesAreAsDocumented) {
    const Bytes frame = encode_frame(ByeMsg{});
    const Bytes expected{std::byte{'I'}, std::byte{'W'}, std::byte{'V'}, std::byte{'P'},
                         std::byte{1},   std::byte{0},   std::byte{8},   std::byte{0},
                         std::byte{1},   std::byte{0},   std::byte{0},   std::byte{0},
                         std::byte{1}};  // bye's payload: its layout version byte
    EXPECT_EQ(frame, expected);
}

TEST(RemoteProtocol, EveryTruncationThrows) {
    for (const RemoteMessage& m : samples()) {
        SCOPED_TRACE(to_string(type_of(m)));
        const Bytes frame = encode_frame(m);
        for (std::size_t n = 0; n < frame.size(); ++n)
            EXPECT_THROW(decode_frame(std::span(frame).first(n)), WireError) << n << " bytes";
        // The header may also say the shorter length: the payload decoder sees the cut.
        const Bytes payload = encode_payload(m);
        for (std::size_t n = 0; n < payload.size(); ++n)
            EXPECT_THROW(decode_payload(type_of(m), std::span(payload).first(n)), WireError)
                << n << " bytes";
    }
}

TEST(RemoteProtocol, TrailingBytesThrow) {
    for (const RemoteMessage& m : samples()) {
        Bytes frame = encode_frame(m);
        frame.push_back(std::byte{0});
        EXPECT_NE(wire_error_of([&] { decode_frame(frame); }, "trailing").find("trailing bytes"),
                  std::string::npos);
        Bytes payload = encode_payload(m);
        payload.push_back(std::byte{0});
        expect_view_wire_error(type_of(m), payload, "1 trailing bytes");
    }
}

TEST(RemoteProtocol, HeaderFaultsNameTheField) {
    const Bytes good = encode_frame(sample_group());
    struct Fault {
        std::size_t offset;
        std::byte value;
        const char* expected;
    };
    const Fault faults[] = {
        {0, std::byte{'X'}, "magic: expected 49 57 56 50"},
        {3, std::byte{0}, "magic"},
        {4, std::byte{2}, "version: expected 1, got 2"},
        {5, std::byte{1}, "version: expected 1, got 257"},
        {6, std::byte{0}, "type: expected 1..11, got 0"},
        {6, std::byte{12}, "type: expected 1..11, got 12"},
        {7, std::byte{1}, "type: expected 1..11, got 260"},
    };
    for (const Fault& f : faults) {
        Bytes bytes = good;
        bytes[f.offset] = f.value;
        const std::string what = wire_error_of([&] { decode_frame(bytes); }, f.expected);
        EXPECT_NE(what.find("view protocol header"), std::string::npos) << what;
        EXPECT_NE(what.find(f.expected), std::string::npos) << what;
    }
}

TEST(RemoteProtocol, OversizedLengthThrowsNamingTheType) {
    Bytes frame = encode_frame(sample_group());
    const std::uint32_t limit = static_cast<std::uint32_t>(frame.size() - kHeaderBytes) - 1;
    const std::string what = wire_error_of([&] { decode_frame(frame, limit); }, "length");
    EXPECT_NE(what.find("length: " + std::to_string(limit + 1) + " bytes is over the limit of " +
                        std::to_string(limit) + " (group message)"),
              std::string::npos)
        << what;
    EXPECT_NO_THROW(decode_frame(frame, limit + 1));
}

TEST(RemoteProtocol, MakeErrorGivesOneBoundedPrintableLine) {
    const ErrorMsg m =
        make_error(ErrorCode::internal, "bad\nline \xc3\xa9" + std::string(600, 'x'));
    EXPECT_EQ(m.text.size(), kMaxErrorTextBytes);
    EXPECT_EQ(m.text.substr(0, 11), "bad?line ??");
    EXPECT_EQ(decode_frame(encode_frame(m)), RemoteMessage(m));
}

// ---- the FrameParser ----------------------------------------------------------------------------

std::vector<RemoteMessage> parse_in_chunks(FrameParser& parser, const Bytes& stream,
                                           const std::vector<std::size_t>& sizes) {
    std::vector<RemoteMessage> out;
    std::size_t at = 0;
    for (std::size_t i = 0; at < stream.size(); ++i) {
        const std::size_t n = std::min(sizes[i % sizes.size()], stream.size() - at);
        std::span<const std::byte> chunk = std::span(stream).subspan(at, n);
        while (!chunk.empty())
            if (auto m = parser.next(chunk)) out.push_back(std::move(*m));
        at += n;
    }
    return out;
}

TEST(RemoteProtocolFraming, OneByteAtATime) {
    const auto messages = samples();
    FrameParser parser;
    EXPECT_EQ(parse_in_chunks(parser, stream_of(messages), {1}), messages);
    EXPECT_EQ(parser.pending_bytes(), 0u);
}

TEST(RemoteProtocolFraming, RandomChunkSizes) {
    std::vector<RemoteMessage> messages = samples();
    for (const RemoteMessage& m : samples()) messages.push_back(m);  // twice, back to back
    const Bytes stream = stream_of(messages);
    std::mt19937 rng(12);
    for (int trial = 0; trial < 50; ++trial) {
        std::vector<std::size_t> sizes(37);
        for (auto& s : sizes) s = std::uniform_int_distribution<std::size_t>(1, 300)(rng);
        FrameParser parser;
        EXPECT_EQ(parse_in_chunks(parser, stream, sizes), messages) << "trial " << trial;
        EXPECT_EQ(parser.pending_bytes(), 0u);
    }
    // The whole stream in one chunk: one message per call, the rest left in the chunk.
    FrameParser parser;
    EXPECT_EQ(parse_in_chunks(parser, stream, {stream.size()}), messages);
}

TEST(RemoteProtocolFraming, AStreamCutShortLeavesBytesPending) {
    const Bytes frame = encode_frame(sample_request());
    FrameParser parser;
    std::span<const std::byte> chunk = std::span(frame).first(frame.size() - 1);
    EXPECT_FALSE(parser.next(chunk).has_value());
    EXPECT_TRUE(chunk.empty());
    EXPECT_EQ(parser.pending_bytes(), frame.size() - 1);
}

TEST(RemoteProtocolFraming, ABadHeaderFailsTheParserForGood) {
    Bytes stream = stream_of({sample_hello()});
    const Bytes bad = encode_frame(ByeMsg{});
    const std::size_t bad_at = stream.size();
    stream.insert(stream.end(), bad.begin(), bad.end());
    stream[bad_at + 4] = std::byte{9};  // the second frame's version
    FrameParser parser;
    std::span<const std::byte> chunk(stream);
    EXPECT_EQ(parser.next(chunk), RemoteMessage(sample_hello()));
    EXPECT_NE(wire_error_of([&] { parser.next(chunk); }, "version").find("version"),
              std::string::npos);
    const Bytes good = encode_frame(ByeMsg{});
    std::span<const std::byte> again(good);
    EXPECT_NE(wire_error_of([&] { parser.next(again); }, "version").find("version: expected 1"),
              std::string::npos);
}

TEST(RemoteProtocolFraming, AClaimedLengthIsNotBufferedBeforeItsBytesCome) {
    FrameParser parser;  // the default limit, 64 MiB
    Bytes header(kHeaderBytes);
    put_header(std::span(header).first<kHeaderBytes>(),
               {kProtocolVersion, RemoteTag::group, kDefaultMaxPayloadBytes});
    header.insert(header.end(), 100, std::byte{0});
    std::span<const std::byte> chunk(header);
    EXPECT_FALSE(parser.next(chunk).has_value());
    EXPECT_LE(parser.buffered_capacity(), kHeaderBytes + 200);
    Bytes over(kHeaderBytes);
    put_header(std::span(over).first<kHeaderBytes>(),
               {kProtocolVersion, RemoteTag::group, kDefaultMaxPayloadBytes + 1});
    FrameParser second;
    std::span<const std::byte> c2(over);
    EXPECT_NE(wire_error_of([&] { second.next(c2); }, "length").find("over the limit"),
              std::string::npos);
    EXPECT_EQ(second.buffered_capacity(), kHeaderBytes);
}

TEST(RemoteProtocolFraming, TheCommittedFuzzSeedsDecode) {
    // fuzz/corpus/view_protocol/stream-all (fuzz_view_protocol_seeds): a mode byte, a chunk seed,
    // then one frame of every type. Seeds that no longer decode would fuzz only the error paths.
    std::ifstream in(std::string(ISOWALL_SOURCE_DIR) + "/fuzz/corpus/view_protocol/stream-all",
                     std::ios::binary);
    ASSERT_TRUE(in) << "missing seed";
    const std::vector<char> raw{std::istreambuf_iterator<char>(in), {}};
    ASSERT_GT(raw.size(), 2u);
    std::span<const std::byte> chunk = std::as_bytes(std::span(raw)).subspan(2);
    FrameParser parser;
    std::vector<RemoteTag> types;
    while (!chunk.empty())
        if (auto m = parser.next(chunk)) types.push_back(type_of(*m));
    ASSERT_EQ(types.size(), std::size_t{kLastRemoteTag});
    for (std::uint16_t t = 1; t <= kLastRemoteTag; ++t)
        EXPECT_EQ(types[t - 1], static_cast<RemoteTag>(t));
}

}  // namespace
}  // namespace isowall::remote
