#include "tile/store_client.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <utility>

#include "core/error.h"
#include "core/util.h"
#include "store/store_format.h"

namespace isowall {
namespace {

constexpr double kReceiveSliceS = 0.05;

std::string seconds(double s) {
    char text[32];
    std::snprintf(text, sizeof text, "%g s", s);
    return text;
}

}  // namespace

Message StoreClient::ask_now(const StoreAskMsg& ask) {
    send_message(comm_, kMasterRank, ask);
    Stopwatch waited;
    while (waited.seconds() < timeout_s_) {
        auto e = comm_.receive(kMasterRank, kReceiveSliceS);
        if (!e) continue;
        Message m = decode_message(e->tag, e->bytes);
        if (std::holds_alternative<AliveMsg>(m)) continue;
        const bool meta = std::holds_alternative<StoreMetaMsg>(m);
        const auto* part = std::get_if<StorePartMsg>(&m);
        if ((ask.part == StorePart::meta && meta) ||
            (part && part->part == ask.part && part->index == ask.index))
            return m;
        throw WireError(std::string("expected the store's ") +
                        (ask.part == StorePart::meta ? "metadata" : "octree") +
                        " from the master, got a " + to_string(e->tag) + " message");
    }
    throw std::runtime_error("the master (rank 0) sent no part of the store within " +
                             seconds(timeout_s_) + " (--timeout)");
}

std::shared_ptr<const store::StoreReader> StoreClient::open(const std::string& name,
                                                            const std::filesystem::path& dir) {
    const StoreMetaMsg meta = std::get<StoreMetaMsg>(ask_now({StorePart::meta, 0}));
    if (!meta.is_store)
        throw InputError(name, "--volume",
                         "not found on " + comm_.host() +
                             ", and the master's volume is not a store: only a store made by "
                             "`isowall import` reaches ranks that cannot see the file");
    auto reader = std::make_shared<const store::StoreReader>(
        name, meta.zarray, meta.zattrs, meta.bytes_on_disk,
        [this](glm::ivec3 b) { return chunk(b); });
    layout_ = reader->layout();
    char file[48];
    std::snprintf(file, sizeof file, "store-%016llx.octree",
                  static_cast<unsigned long long>(store::content_key(layout_)));
    octree_ = dir / file;
    copy_octree(meta, octree_);
    return reader;
}

void StoreClient::copy_octree(const StoreMetaMsg& meta, const std::filesystem::path& octree) {
    std::error_code ec;
    if (std::filesystem::file_size(octree, ec) == meta.octree_bytes && !ec) return;
    if (meta.octree_bytes == 0) return;  // none on the master yet: this rank builds its own
    std::filesystem::create_directories(octree.parent_path(), ec);
    // Written under a name of this rank's, then renamed: ranks of one host may copy at once.
    const std::filesystem::path tmp = octree.string() + ".part" + std::to_string(comm_.rank());
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        const std::uint64_t pieces =
            (meta.octree_bytes + kOctreePieceBytes - 1) / kOctreePieceBytes;
        for (std::uint64_t i = 0; i < pieces && out; ++i) {
            const auto part = std::get<StorePartMsg>(ask_now({StorePart::octree, i}));
            const std::uint64_t want =
                std::min(kOctreePieceBytes, meta.octree_bytes - i * kOctreePieceBytes);
            if (part.bytes.size() != want)
                throw WireError("store_part message: octree piece " + std::to_string(i) +
                                " holds " + std::to_string(part.bytes.size()) +
                                " bytes, expected " + std::to_string(want));
            out.write(reinterpret_cast<const char*>(part.bytes.data()),
                      static_cast<std::streamsize>(part.bytes.size()));
        }
        if (!out) {
            std::filesystem::remove(tmp, ec);
            // Not fatal: without the copy the rank builds the octree from the bricks.
            std::fprintf(stderr, "isowall: rank %d: cannot write %s; building the octree here\n",
                         comm_.rank(), tmp.c_str());
            return;
        }
    }
    std::filesystem::rename(tmp, octree, ec);
    if (ec) std::filesystem::remove(tmp, ec);
}

std::vector<std::byte> StoreClient::chunk(glm::ivec3 b) {
    const std::uint64_t index = layout_.brick_index(b);
    std::unique_lock lock(mutex_);
    if (failed_) throw std::runtime_error(*failed_);
    // The pager asks once a brick (a brick loading is not asked for again), so each slot has one
    // waiter, which erases it.
    const auto [it, fresh] = waiting_.try_emplace(index);
    if (!fresh) throw std::logic_error("chunk " + store::chunk_key(b) + " asked for twice at once");
    auto& slot = it->second;
    send_message(comm_, kMasterRank, StoreAskMsg{StorePart::chunk, index});
    const bool came = arrived_.wait_for(lock, std::chrono::duration<double>(timeout_s_),
                                        [&] { return slot.has_value() || failed_; });
    if (failed_ || !came) waiting_.erase(index);
    if (failed_) throw std::runtime_error(*failed_);
    if (!came)
        throw std::runtime_error("rank " + std::to_string(comm_.rank()) +
                                 ": the master (rank 0) sent no chunk " + store::chunk_key(b) +
                                 " of the store within " + seconds(timeout_s_) + " (--timeout)");
    std::vector<std::byte> bytes = std::move(*slot);
    waiting_.erase(index);
    ++fetched_;
    return bytes;
}

void StoreClient::deliver(StorePartMsg&& part) {
    std::lock_guard lock(mutex_);
    auto it = waiting_.find(part.index);
    if (part.part != StorePart::chunk || it == waiting_.end() || it->second)
        throw WireError("a store_part message for chunk " + std::to_string(part.index) +
                        ", which this rank did not ask for");
    it->second = std::move(part.bytes);
    arrived_.notify_all();
}

void StoreClient::fail(const std::string& why) {
    std::lock_guard lock(mutex_);
    if (!failed_) failed_ = why;
    arrived_.notify_all();
}

std::uint64_t StoreClient::chunks_fetched() const {
    std::lock_guard lock(mutex_);
    return fetched_;
}

}  // namespace isowall
