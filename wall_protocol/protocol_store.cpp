// The store messages (tags 12..14): a tile rank that cannot see the store asks the master for its
// metadata, octree and chunks. Each encoder sits right above its decoder; the decoders check
// what the tile will use (the part, the sizes) so that no caller repeats the checks.
#include "wall_protocol/protocol_store.h"

#include <string>

namespace isowall {

namespace {

// What a store's metadata file may hold: the reader refuses larger ones too.
constexpr std::uint64_t kMaxMetaText = 1 << 20;
// An octree of a store under the 64 TiB cap is far smaller than this.
constexpr std::uint64_t kMaxOctreeBytes = std::uint64_t(1) << 44;
// An index past this is no brick of a store under the 64 TiB cap, and no octree piece.
constexpr std::uint64_t kMaxIndex = std::uint64_t(1) << 40;

StorePart get_part(MessageReader& r) {
    const auto p = r.get<std::uint8_t>();
    if (p > static_cast<std::uint8_t>(StorePart::chunk))
        r.fail("part: expected 0 (meta), 1 (octree) or 2 (chunk), got " + std::to_string(p));
    return static_cast<StorePart>(p);
}

std::uint64_t get_index(MessageReader& r) {
    const auto i = r.get<std::uint64_t>();
    if (i >= kMaxIndex) r.fail("index: expected below 2^40, got " + std::to_string(i));
    return i;
}

std::string get_meta_text(MessageReader& r, const char* field) {
    std::string s = r.get_string();
    if (s.size() > kMaxMetaText)
        r.fail(std::string(field) + ": longer than 1 MiB (" + std::to_string(s.size()) + " bytes)");
    return s;
}

}  // namespace

std::vector<std::byte> encode(const StoreAskMsg& m) {
    MessageWriter w(StoreAskMsg::kVersion);
    w.put(static_cast<std::uint8_t>(m.part));
    w.put(m.index);
    return w.take();
}

StoreAskMsg store_wire::decode_store_ask(std::span<const std::byte> bytes) {
    MessageReader r(bytes, StoreAskMsg::kVersion, "store_ask message");
    StoreAskMsg m;
    m.part = get_part(r);
    m.index = get_index(r);
    if (m.part == StorePart::meta && m.index != 0)
        r.fail("index: expected 0 for the metadata, got " + std::to_string(m.index));
    r.finish();
    return m;
}

std::vector<std::byte> encode(const StoreMetaMsg& m) {
    MessageWriter w(StoreMetaMsg::kVersion);
    w.put(static_cast<std::uint8_t>(m.is_store));
    w.put_string(m.zarray);
    w.put_string(m.zattrs);
    w.put(m.octree_bytes);
    w.put(m.bytes_on_disk);
    return w.take();
}

StoreMetaMsg store_wire::decode_store_meta(std::span<const std::byte> bytes) {
    MessageReader r(bytes, StoreMetaMsg::kVersion, "store_meta message");
    StoreMetaMsg m;
    m.is_store = r.get_bool();
    m.zarray = get_meta_text(r, "zarray");
    m.zattrs = get_meta_text(r, "zattrs");
    m.octree_bytes = r.get<std::uint64_t>();
    if (m.octree_bytes > kMaxOctreeBytes)
        r.fail("octree_bytes: " + std::to_string(m.octree_bytes) + " is past any store's octree");
    m.bytes_on_disk = r.get<std::uint64_t>();
    if (!m.is_store && (!m.zarray.empty() || !m.zattrs.empty() || m.octree_bytes != 0))
        r.fail("a volume that is not a store carries no metadata");
    r.finish();
    return m;
}

std::vector<std::byte> encode(const StorePartMsg& m) {
    MessageWriter w(StorePartMsg::kVersion);
    w.put(static_cast<std::uint8_t>(m.part));
    w.put(m.index);
    w.put_bytes(m.bytes);
    return w.take();
}

StorePartMsg store_wire::decode_store_part(std::span<const std::byte> bytes) {
    MessageReader r(bytes, StorePartMsg::kVersion, "store_part message");
    StorePartMsg m;
    m.part = get_part(r);
    if (m.part == StorePart::meta) r.fail("part: the metadata comes as a store_meta message");
    m.index = get_index(r);
    const auto b = r.get_bytes();
    if (b.size() > kMaxStorePartBytes)
        r.fail("bytes: " + std::to_string(b.size()) + " is more than a part holds (32 MiB)");
    m.bytes.assign(b.begin(), b.end());
    r.finish();
    return m;
}

}  // namespace isowall
