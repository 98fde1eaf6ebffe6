// The slots of a visible message (remote/slot_list.h): varints at each length boundary, both
// forms round-trip, and the encoder picks the smaller (a dense set a bitmap, a sparse set over a
// large range deltas) with the size the layout promises.
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

#include "remote/slot_list.h"
#include "tests/remote_protocol_test_util.h"

namespace isowall::remote {
namespace {

using Bytes = std::vector<std::byte>;

Bytes varint(std::uint32_t v) {
    MessageWriter w(0);
    put_varint(w, v);
    Bytes b = w.take();
    b.erase(b.begin());  // the version byte
    return b;
}

TEST(RemoteSlotList, VarintsTakeSevenBitsAByteLowBitsFirst) {
    EXPECT_EQ(varint(0), Bytes{std::byte{0}});
    EXPECT_EQ(varint(127), Bytes{std::byte{0x7f}});
    EXPECT_EQ(varint(128), (Bytes{std::byte{0x80}, std::byte{0x01}}));
    EXPECT_EQ(varint(300), (Bytes{std::byte{0xac}, std::byte{0x02}}));
    EXPECT_EQ(varint(UINT32_MAX), (Bytes{std::byte{0xff}, std::byte{0xff}, std::byte{0xff},
                                         std::byte{0xff}, std::byte{0x0f}}));
}

TEST(RemoteSlotList, VarintsRoundTripAtEveryLength) {
    for (std::uint32_t v : {0u, 1u, 127u, 128u, 16383u, 16384u, 2097151u, 2097152u, 268435455u,
                            268435456u, UINT32_MAX}) {
        MessageWriter w(1);
        put_varint(w, v);
        const Bytes bytes = w.take();
        EXPECT_EQ(bytes.size() - 1, varint_bytes(v)) << v;
        MessageReader r(bytes, 1, "varint");
        EXPECT_EQ(get_varint(r, "v"), v);
        EXPECT_NO_THROW(r.finish()) << v;
    }
}

// The slots' round trip through a visible message, and the payload's size.
std::size_t round_trip(const std::vector<std::uint32_t>& slots) {
    const VisibleMsg m{42, slots};
    const Bytes payload = encode_payload(m);
    const auto back = std::get<VisibleMsg>(decode_payload(RemoteTag::visible, payload));
    EXPECT_EQ(back.slots, slots);
    EXPECT_EQ(back.request_id, 42u);
    return payload.size();
}

TEST(RemoteSlotList, NoSlotsIsAnEmptyBitmap) {
    EXPECT_EQ(smaller_form({}), SlotForm::bitmap);
    EXPECT_EQ(round_trip({}), 1 + 8 + 1 + 4u);
}

TEST(RemoteSlotList, ADenseSetIsABitmap) {
    // 38 of 50 slots, as the seed rays name after a small rotation: 7 bytes of bits.
    std::vector<std::uint32_t> slots;
    for (std::uint32_t s = 0; s < 50; ++s)
        if (s % 4 != 3) slots.push_back(s);
    ASSERT_EQ(slots.size(), 38u);
    EXPECT_EQ(smaller_form(slots), SlotForm::bitmap);
    EXPECT_EQ(bitmap_form_bytes(slots), 1 + 4 + 7u);
    EXPECT_EQ(deltas_form_bytes(slots), 1 + 4 + 38u);
    EXPECT_EQ(round_trip(slots), 1 + 8 + 1 + 4 + 7u);
    EXPECT_EQ(encode_frame(VisibleMsg{42, slots}).size(), kHeaderBytes + 21);
}

TEST(RemoteSlotList, ASparseSetOverALargeRangeIsDeltas) {
    const std::vector<std::uint32_t> slots{3, 200, 70000, 1048575};
    EXPECT_EQ(smaller_form(slots), SlotForm::deltas);
    // 3 (1 byte), 197 (2), 69800 (3), 978575 (3).
    EXPECT_EQ(deltas_form_bytes(slots), 1 + 4 + 9u);
    EXPECT_EQ(round_trip(slots), 1 + 8 + 1 + 4 + 9u);
}

TEST(RemoteSlotList, ATieGoesToTheBitmap) {
    // Slots 0 and 8: a bitmap of 9 bits (2 bytes), deltas 0 and 8 (1 byte each).
    const std::vector<std::uint32_t> tie{0, 8};
    EXPECT_EQ(bitmap_form_bytes(tie), deltas_form_bytes(tie));
    EXPECT_EQ(smaller_form(tie), SlotForm::bitmap);
    EXPECT_EQ(round_trip(tie), 1 + 8 + 1 + 4 + 2u);
}

TEST(RemoteSlotList, EverySlotBelowTheLimitRoundTrips) {
    std::vector<std::uint32_t> all(kMaxVisibleKeys);
    std::iota(all.begin(), all.end(), 0u);
    EXPECT_EQ(round_trip(all), 1 + 8 + 1 + 4 + kMaxVisibleKeys / 8);
    EXPECT_EQ(round_trip({static_cast<std::uint32_t>(kMaxVisibleKeys - 1)}), 1 + 8 + 1 + 4 + 3u);
}

}  // namespace
}  // namespace isowall::remote
