#pragma once
// The master's side of a store that some tile ranks cannot see (tile/store_client.h): the answer
// to each store_ask, read from the master's own copy.
#include <cstdint>
#include <cstdio>
#include <filesystem>

#include "comm/comm.h"
#include "store/store_reader.h"
#include "wall_protocol/protocol.h"

namespace isowall {

// The store_meta or store_part message that answers `ask`. `store` is the master's volume when it
// is a store (null otherwise: a meta ask is answered "not a store", any other ask is a WireError),
// `octree` its octree file. A chunk that cannot be read is the reader's InputError naming the
// store and the chunk; a chunk index past the store or an octree piece past its end is a
// WireError.
Message answer_store_ask(const StoreAskMsg& ask, const store::StoreReader* store,
                         const std::filesystem::path& octree);

// What the master sent, for the wall's report.
struct StoreSent {
    std::uint64_t chunks = 0, chunk_bytes = 0, octree_bytes = 0;
    std::uint64_t asking_ranks = 0;  // ranks that asked for the metadata
    // Sends `answer` to `rank` and counts it.
    void add(int rank, const Message& answer, Comm& comm);
};

// "store: 850 chunks (5.0 MiB) and 2.1 MiB of octree sent to 4 ranks that cannot see it", when
// any rank asked; nothing otherwise.
void print_store_sent(std::FILE* out, const StoreSent& sent);

}  // namespace isowall
