#include "master/store_server.h"

#include <fstream>
#include <string>

namespace isowall {
namespace {

// Bytes [offset, offset + n) of `file`, fewer at its end; a piece past the end is a WireError.
std::vector<std::byte> read_piece(const std::filesystem::path& file, std::uint64_t index) {
    std::error_code ec;
    const std::uint64_t size = std::filesystem::file_size(file, ec);
    const std::uint64_t offset = index * kOctreePieceBytes;
    if (ec || offset >= size)
        throw WireError("store_ask message: octree piece " + std::to_string(index) +
                        " is past the octree's end");
    std::vector<std::byte> bytes(std::min(kOctreePieceBytes, size - offset));
    std::ifstream in(file, std::ios::binary);
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!in) throw std::runtime_error(file.string() + ": cannot read the octree to send it");
    return bytes;
}

}  // namespace

Message answer_store_ask(const StoreAskMsg& ask, const store::StoreReader* store,
                         const std::filesystem::path& octree) {
    if (ask.part == StorePart::meta) {
        StoreMetaMsg meta;
        if (store) {
            meta.is_store = true;
            meta.zarray = store->zarray_text();
            meta.zattrs = store->zattrs_text();
            std::error_code ec;
            const auto size = std::filesystem::file_size(octree, ec);
            meta.octree_bytes = ec ? 0 : size;
            meta.bytes_on_disk = store->bytes_on_disk();
        }
        return meta;
    }
    if (!store) throw WireError("store_ask message: the volume is not a store");
    if (ask.part == StorePart::octree)
        return StorePartMsg{ask.part, ask.index, read_piece(octree, ask.index)};
    const store::StoreLayout& l = store->layout();
    if (ask.index >= l.chunk_count())
        throw WireError("store_ask message: chunk " + std::to_string(ask.index) +
                        " of a store of " + std::to_string(l.chunk_count()));
    return StorePartMsg{ask.part, ask.index, store->read_packed(l.brick_at(ask.index))};
}

void StoreSent::add(int rank, const Message& answer, Comm& comm) {
    if (std::holds_alternative<StoreMetaMsg>(answer)) ++asking_ranks;
    if (const auto* p = std::get_if<StorePartMsg>(&answer)) {
        if (p->part == StorePart::chunk) {
            ++chunks;
            chunk_bytes += p->bytes.size();
        } else {
            octree_bytes += p->bytes.size();
        }
    }
    comm.send(rank, tag_of(answer), encode(answer));
}

void print_store_sent(std::FILE* out, const StoreSent& s) {
    if (s.asking_ranks == 0) return;
    std::fprintf(out,
                 "store: %llu chunks (%.1f MiB) and %.1f MiB of octree sent by the master to %llu "
                 "rank(s) that read it from there\n",
                 static_cast<unsigned long long>(s.chunks), double(s.chunk_bytes) / 1048576.0,
                 double(s.octree_bytes) / 1048576.0,
                 static_cast<unsigned long long>(s.asking_ranks));
}

}  // namespace isowall
