#pragma once
// A tile rank's store when its host cannot see the folder (a display node without the shared file
// system, as on the dissertation's wall): the store's metadata and octree come from the master at
// start-up, and while frames run every chunk the rank's pager needs comes from the master too
// (wall_protocol/protocol.h: store_ask, store_meta, store_part). The chunks arrive compressed, as
// on the master's disk, and the reader checks each as if it had read it: a damaged chunk is still
// one line naming the store and the chunk.
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "comm/comm.h"
#include "store/store_reader.h"
#include "wall_protocol/protocol.h"

namespace isowall {

class StoreClient {
  public:
    // `timeout_s`: how long one answer may take (--timeout) before the rank gives up.
    StoreClient(Comm& comm, double timeout_s) : comm_(comm), timeout_s_(timeout_s) {}

    // At start-up, before the communication thread runs (this thread receives): the master's
    // store named `name`, with its octree copied into the folder `dir` (octree_file(); a copy of
    // the same size already there is kept). InputError naming `name` when the master's volume is
    // not a store.
    std::shared_ptr<const store::StoreReader> open(const std::string& name,
                                                   const std::filesystem::path& dir);
    // The octree's copy: "store-KEY.octree" in open()'s folder, KEY the store's content key.
    const std::filesystem::path& octree_file() const { return octree_; }

    // From the pager's threads while frames run: brick b's compressed chunk. Throws when the
    // master does not answer within the timeout or the communication thread has failed.
    std::vector<std::byte> chunk(glm::ivec3 b);
    // From the communication thread: an answer to chunk(), and the end of all answers.
    void deliver(StorePartMsg&& part);
    void fail(const std::string& why);

    std::uint64_t chunks_fetched() const;

  private:
    // Start-up only: sends `ask` and receives until the master's answer.
    Message ask_now(const StoreAskMsg& ask);
    void copy_octree(const StoreMetaMsg& meta, const std::filesystem::path& octree);

    Comm& comm_;
    double timeout_s_;
    store::StoreLayout layout_;
    std::filesystem::path octree_;
    mutable std::mutex mutex_;
    std::condition_variable arrived_;
    std::map<std::uint64_t, std::optional<std::vector<std::byte>>> waiting_;
    std::optional<std::string> failed_;
    std::uint64_t fetched_ = 0;
};

}  // namespace isowall
