// The store messages (store_ask, store_meta, store_part: a tile rank that cannot see the store
// asks the master): each round-trips, and each value the tile or the master would use wrongly is
// refused on the wire, naming the field. (Truncation, versions, trailing bytes and mutations run
// over these messages too, in protocol_malformed_test.cpp through samples().)
#include <gtest/gtest.h>

#include <string>

#include "tests/protocol_test_util.h"

namespace isowall {
namespace {

using namespace protocol_testing;

TEST(ProtocolStore, EveryStoreMessageRoundTrips) {
    expect_round_trip(StoreAskMsg{});  // the metadata
    expect_round_trip(StoreAskMsg{StorePart::octree, 12});
    expect_round_trip(StoreAskMsg{StorePart::chunk, (std::uint64_t(1) << 40) - 1});
    expect_round_trip(StoreMetaMsg{});  // not a store
    expect_round_trip(sample_store_meta());
    expect_round_trip(sample_store_part());
    expect_round_trip(StorePartMsg{StorePart::chunk, 0, {}});
    StorePartMsg largest{StorePart::chunk, 9, std::vector<std::byte>(kMaxStorePartBytes)};
    expect_round_trip(largest);
}

TEST(ProtocolStore, BadStoreMessagesThrowNamingTheField) {
    StoreAskMsg bad_part{StorePart::chunk, 1};
    auto bytes = encode(bad_part);
    bytes[1] = std::byte{3};  // the part, right after the version byte
    expect_wire_error(Tag::store_ask, bytes, "part");
    expect_wire_error(Tag::store_ask, encode(StoreAskMsg{StorePart::meta, 4}), "index");
    expect_wire_error(Tag::store_ask, encode(StoreAskMsg{StorePart::chunk, std::uint64_t(1) << 40}),
                      "index");

    StoreMetaMsg not_store = sample_store_meta();
    not_store.is_store = false;
    expect_wire_error(Tag::store_meta, encode(not_store), "not a store");
    StoreMetaMsg long_meta = sample_store_meta();
    long_meta.zattrs.assign((1 << 20) + 1, ' ');
    expect_wire_error(Tag::store_meta, encode(long_meta), "zattrs");
    StoreMetaMsg huge_octree = sample_store_meta();
    huge_octree.octree_bytes = ~std::uint64_t(0);
    expect_wire_error(Tag::store_meta, encode(huge_octree), "octree_bytes");

    expect_wire_error(Tag::store_part, encode(StorePartMsg{StorePart::meta, 0, {}}), "part");
    StorePartMsg too_big{StorePart::chunk, 1, std::vector<std::byte>(kMaxStorePartBytes + 1)};
    expect_wire_error(Tag::store_part, encode(too_big), "bytes");
}

}  // namespace
}  // namespace isowall
