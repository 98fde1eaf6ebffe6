// The remote-viewing protocol, malformed fields: each check of each decoder throws a WireError
// naming the message and the field, and a claimed huge count or length throws before anything is
// allocated (the largest allocation is measured by replacing operator new, as in
// protocol_malformed_test.cpp).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <new>
#include <string>

#include "remote/slot_list.h"
#include "tests/largest_allocation.h"
#include "tests/remote_protocol_test_util.h"

namespace isowall::remote {
namespace {

using test::largest_allocation_in;

using namespace remote_testing;
using Bytes = std::vector<std::byte>;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// A valid sample with one field broken, and what the error must name. The encoders write what
// they are given, so a broken message is a sample with one field changed.
template <class M>
struct Fault {
    const char* field;
    void (*apply)(M&);
};

template <class M>
void expect_faults(const M& sample, std::initializer_list<Fault<M>> faults) {
    for (const Fault<M>& f : faults) {
        M m = sample;
        f.apply(m);
        expect_view_wire_error(M::kTag, encode_payload(m), f.field);
    }
}

TEST(RemoteProtocolMalformed, AllocationsAreSeen) {
    GroupMsg m = sample_group();
    m.encoded.assign(100000, std::byte{7});
    const Bytes bytes = encode_payload(m);
    EXPECT_GE(largest_allocation_in([&] { decode_payload(RemoteTag::group, bytes); }), 100000u);
}

TEST(RemoteProtocolMalformed, HelloFields) {
    expect_faults<HelloMsg>(
        sample_hello(),
        {{"dataset: expected a name", [](HelloMsg& m) { m.dataset.clear(); }},
         {"dataset: 257 bytes, expected at most 256",
          [](HelloMsg& m) { m.dataset.assign(257, 'a'); }},
         {"dataset: byte 2 is 10", [](HelloMsg& m) { m.dataset[2] = '\n'; }},
         {"dataset: byte 0 is 195", [](HelloMsg& m) { m.dataset = "\xc3\xa9"; }},
         {"token: 257 bytes", [](HelloMsg& m) { m.token.assign(257, 't'); }},
         {"token: byte 1 is 0", [](HelloMsg& m) { m.token = std::string("a\0b", 3); }}});
    HelloMsg ok = sample_hello();
    ok.token.clear();
    ok.dataset.assign(kMaxDatasetNameBytes, '~');
    EXPECT_NO_THROW(decode_payload(RemoteTag::hello, encode_payload(ok)));
}

// A hello that joins a shared session is version 2 and round-trips; one without a role is
// version 1, as before sessions, so older servers and the page's hello stay valid.
TEST(RemoteProtocolMalformed, SharedHelloFields) {
    const HelloMsg shared = sample_shared_hello();
    EXPECT_EQ(std::get<HelloMsg>(decode_payload(RemoteTag::hello, encode_payload(shared))), shared);
    EXPECT_EQ(encode_payload(shared)[0], std::byte{2});
    EXPECT_EQ(encode_payload(sample_hello())[0], std::byte{1});
    expect_faults<HelloMsg>(shared,
                            {{"session: expected a name", [](HelloMsg& m) { m.session.clear(); }},
                             {"session: 65 bytes", [](HelloMsg& m) { m.session.assign(65, 's'); }},
                             {"session: byte 0 is 9", [](HelloMsg& m) { m.session = "\tx"; }},
                             {"role: 3, expected 1 (presenter) or 2 (follower)",
                              [](HelloMsg& m) { m.role = static_cast<SessionRole>(3); }}});
}

// A hello that takes exact values is version 3, with or without a role; its flag is 1 (0 is
// version 1 or 2's), and without a role it names no session.
TEST(RemoteProtocolMalformed, ExactHelloFields) {
    HelloMsg exact = sample_exact_hello();
    EXPECT_EQ(encode_payload(exact)[0], std::byte{3});
    EXPECT_EQ(std::get<HelloMsg>(decode_payload(RemoteTag::hello, encode_payload(exact))), exact);
    HelloMsg presenter = sample_shared_hello();
    presenter.takes_exact = true;
    presenter.role = SessionRole::presenter;
    EXPECT_EQ(std::get<HelloMsg>(decode_payload(RemoteTag::hello, encode_payload(presenter))),
              presenter);
    std::vector<std::byte> bytes = encode_payload(exact);
    bytes.back() = std::byte{2};
    std::string what;
    try {
        decode_payload(RemoteTag::hello, bytes);
    } catch (const WireError& e) {
        what = e.what();
    }
    EXPECT_NE(what.find("takes_exact: expected 0 or 1, got 2"), std::string::npos) << what;
    // A version 3 hello that says 0 would encode back as version 1: one message, one encoding.
    bytes.back() = std::byte{0};
    what.clear();
    try {
        decode_payload(RemoteTag::hello, bytes);
    } catch (const WireError& e) {
        what = e.what();
    }
    EXPECT_NE(what.find("takes_exact: 0 in a version 3 hello"), std::string::npos) << what;
    expect_faults<HelloMsg>(
        exact, {{"session: a name without a role", [](HelloMsg& m) { m.session.assign(1, 'x'); }},
                {"role: 3, expected 0 (none), 1 (presenter) or 2 (follower)",
                 [](HelloMsg& m) { m.role = static_cast<SessionRole>(3); }}});
}

TEST(RemoteProtocolMalformed, ExactFields) {
    expect_faults<ExactMsg>(
        sample_exact(),
        {{"key.level: expected 0..30, got 31", [](ExactMsg& m) { m.key.level = 31; }},
         {"key.iso: expected a finite number", [](ExactMsg& m) { m.key.iso = kNaN; }}});
    EXPECT_NO_THROW(decode_payload(RemoteTag::exact, encode_payload(ExactMsg{})));
}

TEST(RemoteProtocolMalformed, SessionFields) {
    expect_faults<SessionMsg>(
        sample_session(),
        {{"session: expected a name", [](SessionMsg& m) { m.session.clear(); }},
         {"presenter: 129 bytes", [](SessionMsg& m) { m.presenter.assign(129, 'p'); }},
         {"presenter: byte 0 is 127", [](SessionMsg& m) { m.presenter.assign(1, char(0x7f)); }}});
}

TEST(RemoteProtocolMalformed, DecodeRateFields) {
    using E = DecodeRateMsg::Entry;
    expect_faults<DecodeRateMsg>(
        sample_decode_rate(),
        {{"entries: 6, expected at most 5", [](DecodeRateMsg& m) { m.entries.assign(6, E{}); }},
         {"entries.encoding: 5, expected at most 4",
          [](DecodeRateMsg& m) { m.entries[1].encoding = 5; }},
         {"entries.encoding: 3 after 3, expected ascending",
          [](DecodeRateMsg& m) { m.entries[1].encoding = 3; }},
         {"entries.seconds: expected a finite number",
          [](DecodeRateMsg& m) { m.entries[1].seconds = kNaN; }},
         {"entries.seconds: -1.000000, expected >= 0",
          [](DecodeRateMsg& m) { m.entries[0].seconds = -1; }}});
    EXPECT_NO_THROW(decode_payload(RemoteTag::decode_rate, encode_payload(DecodeRateMsg{})));
}

TEST(RemoteProtocolMalformed, ReadyFields) {
    expect_faults<ReadyMsg>(
        sample_ready(),
        {{"bounds.min.y: expected a finite number", [](ReadyMsg& m) { m.bounds.min.y = kNaN; }},
         {"bounds.max.z: expected a finite number", [](ReadyMsg& m) { m.bounds.max.z = kInf; }},
         {"bounds: expected min <= max", [](ReadyMsg& m) { m.bounds.min.x = 5; }},
         // Once "--zoom: ... expected at least inf" in the client, though no --zoom was given.
         {"bounds: expected a box at most 1e7 units a side",
          [](ReadyMsg& m) { m.bounds.max.x = 1e30f; }},
         {"value_min: expected a finite number", [](ReadyMsg& m) { m.value_min = kNaN; }},
         {"value_max: expected >= value_min", [](ReadyMsg& m) { m.value_max = -2000; }},
         {"dims.y: expected 1..2147483647, got 0", [](ReadyMsg& m) { m.dims.y = 0; }},
         {"dims.z: expected 1..2147483647, got -3", [](ReadyMsg& m) { m.dims.z = -3; }},
         {"spacing: expected positive", [](ReadyMsg& m) { m.spacing.x = 0; }},
         {"spacing.z: expected a finite number", [](ReadyMsg& m) { m.spacing.z = -kInf; }},
         {"axes.y.x: expected a finite number", [](ReadyMsg& m) { m.axes[1].x = kNaN; }},
         {"axes.z: expected a unit vector", [](ReadyMsg& m) { m.axes[2] *= 2.0f; }},
         // A mirrored frame would draw the patient mirror-imaged: the server sends rotations.
         {"axes: expected a rotation", [](ReadyMsg& m) { m.axes[0] = -m.axes[0]; }}});
}

TEST(RemoteProtocolMalformed, RequestFields) {
    expect_faults<RequestMsg>(
        sample_request(),
        {{"camera.eye: expected finite", [](RequestMsg& m) { m.view.camera.eye.x = kNaN; }},
         {"frustum.top: expected a finite number",
          [](RequestMsg& m) { m.view.frustum.top = kInf; }},
         {"view.width: expected 1..32768, got 0", [](RequestMsg& m) { m.view.width = 0; }},
         {"view.height: expected 1..32768, got 40000",
          [](RequestMsg& m) { m.view.height = 40000; }},
         {"view.iso: expected a finite number", [](RequestMsg& m) { m.view.iso = kNaN; }},
         {"view.camera: ", [](RequestMsg& m) { m.view.camera.target = m.view.camera.eye; }},
         {"camera.projection: expected 0",
          [](RequestMsg& m) { m.view.camera.projection = static_cast<Projection>(2); }},
         // A frustum that cannot be drawn (remote/request_checks.h), named by its field.
         {"view.frustum.left: expected a number within 1e+09 of zero, got -1e+38",
          [](RequestMsg& m) { m.view.frustum.left = -1e38f; }},
         {"view.frustum.right: expected more than left",
          [](RequestMsg& m) { m.view.frustum.right = m.view.frustum.left; }},
         {"view.frustum.far_z: expected more than near_z",
          [](RequestMsg& m) { m.view.frustum.far_z = 0.25f; }}});
    Bytes bytes = encode_payload(sample_request());
    bytes[bytes.size() - 2] = std::byte{3};  // lod
    expect_view_wire_error(RemoteTag::request, bytes,
                           "lod: expected 0 (off), 1 (on) or 2 (the server chooses), got 3");
    bytes[bytes.size() - 2] = std::byte{1};
    bytes.back() = std::byte{255};  // cached_groups
    expect_view_wire_error(RemoteTag::request, bytes, "cached_groups: expected 0 or 1, got 255");
}

TEST(RemoteProtocolMalformed, GroupFields) {
    expect_faults<GroupMsg>(
        sample_group(),
        {{"key.seed.x: expected 0..2147483647, got -1", [](GroupMsg& m) { m.key.seed.x = -1; }},
         {"key.level: expected 0..30, got 31", [](GroupMsg& m) { m.key.level = 31; }},
         {"key.level: expected 0..30, got -1", [](GroupMsg& m) { m.key.level = -1; }},
         {"key.iso: expected a finite number", [](GroupMsg& m) { m.key.iso = -kInf; }}});
    Bytes bytes = encode_payload(sample_group());
    const std::size_t refinement_at = 1 + 8 + 12 + 4 + 8;
    bytes[refinement_at] = std::byte{3};
    expect_view_wire_error(RemoteTag::group, bytes, "key.refinement: expected 0 or 1, got 3");
    bytes[refinement_at] = std::byte{0};
    bytes[refinement_at + 1] = std::byte{2};
    expect_view_wire_error(RemoteTag::group, bytes, "draw_from_next_frame: expected 0 or 1, got 2");
    GroupMsg big = sample_group();
    big.encoded.assign(kMaxGroupBytes + 1, std::byte{1});
    expect_view_wire_error(RemoteTag::group, encode_payload(big), "encoded: 33554433 bytes");
}

TEST(RemoteProtocolMalformed, GroupWithAHugeLengthThrowsWithoutAllocating) {
    for (std::uint64_t length :
         {std::uint64_t{5}, std::uint64_t{1} << 40, std::numeric_limits<std::uint64_t>::max()}) {
        Bytes bytes = encode_payload(sample_group());
        ASSERT_GE(bytes.size(), 12u);
        // Drop the blob (4 bytes) and its length (8): erase, not resize, which GCC 12 under
        // -O2 and sanitizers mistakes for a memset of a wrapped size (-Wstringop-overflow).
        bytes.erase(bytes.end() - 12, bytes.end());
        MessageWriter w(0);
        w.put(length);
        w.put(std::uint32_t{0x01020304});  // 4 bytes, fewer than the length
        bytes.insert(bytes.end(), w.bytes().begin() + 1, w.bytes().end());
        const auto largest = largest_allocation_in(
            [&] { expect_view_wire_error(RemoteTag::group, bytes, "longer than the message"); });
        EXPECT_LT(largest, 4096u) << "length " << length;
    }
}

// A visible message's bytes up to its slots: version, request id, form.
MessageWriter visible_head(SlotForm form) {
    MessageWriter w(VisibleMsg::kVersion);
    w.put(std::uint64_t{9});
    w.put(static_cast<std::uint8_t>(form));
    return w;
}

TEST(RemoteProtocolMalformed, VisibleBitmapFields) {
    MessageWriter past = visible_head(SlotForm::bitmap);
    past.put(std::uint32_t{10});  // two bytes; bit 10 (byte 1, bit 2) is past the count
    past.put(std::uint8_t{0x01});
    past.put(std::uint8_t{0x06});
    expect_view_wire_error(RemoteTag::visible, past.take(),
                           "slots: bit 10 is set, expected none at or past the bit count 10");
    MessageWriter cut = visible_head(SlotForm::bitmap);
    cut.put(std::uint32_t{17});  // three bytes of bits, two given
    cut.put(std::uint16_t{0xffff});
    expect_view_wire_error(RemoteTag::visible, cut.take(),
                           "slots: a bitmap of 17 bits takes 3 bytes, 2 left");
    MessageWriter over = visible_head(SlotForm::bitmap);
    over.put(static_cast<std::uint32_t>(kMaxVisibleKeys + 1));
    expect_view_wire_error(RemoteTag::visible, over.take(),
                           "slots: bit count 1048577, expected at most 1048576");
    MessageWriter form = visible_head(SlotForm::bitmap);
    Bytes bytes = form.take();
    bytes.back() = std::byte{2};
    expect_view_wire_error(RemoteTag::visible, bytes,
                           "form: expected 0 (bitmap) or 1 (deltas), got 2");
}

// A deltas-form visible message of `count` with `varints` as raw bytes after it.
Bytes visible_deltas(std::uint32_t count, std::initializer_list<std::uint8_t> varints) {
    MessageWriter w = visible_head(SlotForm::deltas);
    w.put(count);
    for (const std::uint8_t b : varints) w.put(b);
    return w.take();
}

TEST(RemoteProtocolMalformed, VisibleDeltasFields) {
    struct Case {
        Bytes bytes;
        const char* field;
    };
    const Case cases[] = {
        {visible_deltas(3, {5, 1, 0}), "slots[2]: gap 0, expected at least 1"},
        {visible_deltas(1, {0x80, 0x80, 0x80, 0x80, 0x80, 0x01}),
         "slots[0]: varint longer than 5 bytes"},
        {visible_deltas(2, {1, 0x80, 0x80}), "slots[1]: the varint runs past the end"},
        {visible_deltas(1, {0xff, 0xff, 0xff, 0xff, 0x1f}),
         "slots[0]: varint 8589934591, expected less than 2^32"},
        {visible_deltas(1, {0x80, 0x80, 0x40}), "slots[0]: slot 1048576, expected less than"},
        {visible_deltas(2, {0xff, 0xff, 0x3f, 0x01}), "slots[1]: slot 1048576, expected less than"},
        {visible_deltas(3, {1, 2}), "slots: count 3 is larger than the 2 bytes left"},
    };
    for (const Case& c : cases) expect_view_wire_error(RemoteTag::visible, c.bytes, c.field);
    // The encoder writes what it is given: a slot over the limit goes out, and is refused.
    VisibleMsg far{9, {1, static_cast<std::uint32_t>(kMaxVisibleKeys)}};
    expect_view_wire_error(RemoteTag::visible, encode_payload(far),
                           "slots[1]: slot 1048576, expected less than 1048576");
}

// A set of slots has one encoding, the encoder's, so what decodes encodes back to its bytes (the
// fuzz harness found a deltas form re-encoded as the smaller bitmap).
TEST(RemoteProtocolMalformed, VisibleAcceptsOnlyTheEncodersBytes) {
    MessageWriter slack = visible_head(SlotForm::bitmap);
    slack.put(std::uint32_t{16});  // slot 0 only: the count should be 1
    slack.put(std::uint16_t{0x0001});
    expect_view_wire_error(RemoteTag::visible, slack.take(),
                           "slots: bit count 16 but bit 15 is clear, expected the highest slot");
    expect_view_wire_error(RemoteTag::visible, visible_deltas(1, {0x81, 0x00}),
                           "slots[0]: varint of 2 bytes ends in a zero byte");
    expect_view_wire_error(RemoteTag::visible, visible_deltas(10, {0, 1, 1, 1, 1, 1, 1, 1, 1, 1}),
                           "form: 1, but the slots take 7 bytes as a bitmap and 15 as deltas");
    MessageWriter sparse = visible_head(SlotForm::bitmap);
    sparse.put(std::uint32_t{100});  // slot 99 alone: 13 bytes of bits, where one varint does
    for (int i = 0; i < 12; ++i) sparse.put(std::uint8_t{0});
    sparse.put(std::uint8_t{0x08});
    expect_view_wire_error(RemoteTag::visible, sparse.take(),
                           "form: 0, but the slots take 18 bytes as a bitmap and 6 as deltas");
}

TEST(RemoteProtocolMalformed, VisibleWithAHugeCountThrowsWithoutAllocating) {
    for (std::uint32_t count : {std::uint32_t{4}, std::uint32_t{1} << 30, UINT32_MAX}) {
        const Bytes bytes = visible_deltas(count, {1, 2, 3});
        const auto largest = largest_allocation_in([&] {
            expect_view_wire_error(RemoteTag::visible, bytes, "is larger than the 3 bytes left");
        });
        EXPECT_LT(largest, 4096u) << "count " << count;
    }
    MessageWriter w = visible_head(SlotForm::bitmap);
    w.put(UINT32_MAX);
    const Bytes bitmap = w.take();
    const auto largest = largest_allocation_in(
        [&] { expect_view_wire_error(RemoteTag::visible, bitmap, "slots: bit count 4294967295"); });
    EXPECT_LT(largest, 4096u);
}

TEST(RemoteProtocolMalformed, ErrorFields) {
    expect_faults<ErrorMsg>(
        sample_error(),
        {{"code: expected 1..7, got 0", [](ErrorMsg& m) { m.code = static_cast<ErrorCode>(0); }},
         {"code: expected 1..7, got 8", [](ErrorMsg& m) { m.code = static_cast<ErrorCode>(8); }},
         {"text: byte 3 is 10", [](ErrorMsg& m) { m.text = "one\ntwo"; }},
         {"text: 257 bytes", [](ErrorMsg& m) { m.text.assign(257, 'e'); }}});
}

TEST(RemoteProtocolMalformed, WrongLayoutVersionThrows) {
    for (const RemoteMessage& m : samples()) {
        Bytes bytes = encode_payload(m);
        bytes[0] = std::byte{99};
        const int version = std::visit([](const auto& msg) { return int(msg.kVersion); }, m);
        expect_view_wire_error(type_of(m), bytes,
                               "version 99, expected " + std::to_string(version));
    }
}

TEST(RemoteProtocolMalformed, AnUnknownTypeThrows) {
    EXPECT_THROW(decode_payload(static_cast<RemoteTag>(0), encode_payload(ByeMsg{})), WireError);
    EXPECT_THROW(decode_payload(static_cast<RemoteTag>(10), encode_payload(ByeMsg{})), WireError);
}

}  // namespace
}  // namespace isowall::remote
