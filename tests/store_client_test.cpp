// A store read by a rank that cannot see it (bricks over MPI): the tile's StoreClient
// asks, the master's answer_store_ask answers, over the in-process transport. Every voxel comes
// back as imported, the octree is copied, and each failure is one line: a master whose volume is
// not a store, a damaged chunk on the master, a master that does not answer, an answer nobody
// asked for.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <thread>

#include "comm/inproc_comm.h"
#include "core/error.h"
#include "master/store_server.h"
#include "store/open_store.h"
#include "store/store_writer.h"
#include "tests/store_test_util.h"
#include "tests/test_util.h"
#include "tile/store_client.h"
#include "wire/wire.h"

namespace isowall {
namespace {
namespace fs = std::filesystem;

using test::pattern_volume;

// A store with an octree file beside its bricks, as `isowall import` leaves it; this one is only
// bytes, of more than one piece, since the test copies it and never maps it.
constexpr std::size_t kOctreeBytes = kOctreePieceBytes + 12345;

fs::path make_store(const Volume& v, const std::string& name) {
    const fs::path dir = test::scratch_dir(name);
    store::ImportOptions o;
    o.threads = 2;
    store::write_store(v, dir / "store", o);
    std::ofstream(store::octree_file(dir / "store"), std::ios::binary)
        << std::string(kOctreeBytes, 'o');
    return dir / "store";
}

// Rank 0 of a two-rank world: answers store asks from `store` until a quit.
void serve(Comm& comm, const store::StoreReader* store, const fs::path& octree) {
    for (;;) {
        auto e = comm.receive(-1, kForever);
        const Message m = decode_message(e->tag, e->bytes);
        if (std::holds_alternative<QuitMsg>(m)) return;
        StoreSent sent;
        sent.add(e->from, answer_store_ask(std::get<StoreAskMsg>(m), store, octree), comm);
    }
}

// Rank 1's communication thread, as the tile's Receiver does it: store parts to the StoreClient.
struct Delivery {
    Delivery(Comm& comm, StoreClient& r)
        : thread([&comm, &r, this] {
              while (!done) {
                  auto e = comm.receive(0, 0.02);
                  if (!e) continue;
                  r.deliver(std::get<StorePartMsg>(decode_message(e->tag, e->bytes)));
              }
          }) {}
    ~Delivery() {
        done = true;
        thread.join();
    }
    std::atomic<bool> done{false};
    std::thread thread;
};

TEST(StoreClient, EveryVoxelAndTheOctreeComeFromTheMaster) {
    const Volume v = pattern_volume({150, 130, 100});
    const fs::path path = make_store(v, "remote_store");
    const store::StoreReader local(path);
    const fs::path cache = path.parent_path() / "tile-cache";
    InProcWorld world(2);
    std::uint64_t fetched = 0;
    std::thread master([&] { serve(*world.comm(0), &local, store::octree_file(path)); });
    {
        auto comm = world.comm(1);
        StoreClient remote(*comm, 30);
        auto reader = remote.open("far/store", cache);
        EXPECT_EQ(reader->layout().dims, v.dims());
        EXPECT_EQ(reader->bytes_on_disk(), local.bytes_on_disk());
        EXPECT_EQ(remote.octree_file().parent_path(), cache);
        EXPECT_EQ(fs::file_size(remote.octree_file()), fs::file_size(store::octree_file(path)));
        // Under a cap of a few bricks, so bricks are fetched again after eviction.
        store::OpenedStore s = store::open_store(reader, remote.octree_file(),
                                                 store::PagedVoxels::min_cap(reader->layout()));
        Delivery delivery(*comm, remote);
        std::size_t bad = 0;
        const auto a = v.view<std::uint16_t>(), b = s.volume.view<std::uint16_t>();
        for (int z = 0; z < 100; z += 3)
            for (int y = 0; y < 130; y += 2)
                for (int x = 0; x < 150; ++x) bad += a.at(x, y, z) != b.at(x, y, z);
        EXPECT_EQ(bad, 0u);
        fetched = remote.chunks_fetched();
        EXPECT_GE(fetched, reader->layout().chunk_count());
        send_message(*comm, 0, QuitMsg{});
    }
    master.join();
    std::printf("%llu chunks fetched from the master\n", static_cast<unsigned long long>(fetched));
}

TEST(StoreClient, AMasterWhoseVolumeIsNotAStoreIsOneLine) {
    InProcWorld world(2);
    std::thread master([&] { serve(*world.comm(0), nullptr, {}); });
    auto comm = world.comm(1);
    StoreClient remote(*comm, 30);
    try {
        remote.open("/data/head.nrrd", test::scratch_dir("remote_not_store"));
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("/data/head.nrrd"), std::string::npos) << what;
        EXPECT_NE(what.find("not a store"), std::string::npos) << what;
    }
    send_message(*comm, 0, QuitMsg{});
    master.join();
}

TEST(StoreClient, ADamagedChunkOnTheMasterNamesTheStoreAndTheChunk) {
    const fs::path path = make_store(pattern_volume({70, 40, 40}), "remote_damaged");
    const store::StoreReader local(path);
    fs::remove(path / store::chunk_key({1, 0, 0}));
    fs::resize_file(path / store::chunk_key({0, 1, 0}), 5);
    EXPECT_NO_THROW(answer_store_ask({StorePart::chunk, 0}, &local, {}));
    try {
        answer_store_ask({StorePart::chunk, 1}, &local, {});
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(path.string()), std::string::npos) << what;
        EXPECT_NE(what.find("0/0/0/1"), std::string::npos) << what;
    }
    // A damaged chunk goes as it is; the tile refuses it as one read from its own disk, naming
    // the store as the tile knows it and the chunk.
    const auto damaged = std::get<StorePartMsg>(
        answer_store_ask({StorePart::chunk, local.layout().brick_index({0, 1, 0})}, &local, {}));
    EXPECT_EQ(damaged.bytes.size(), 5u);
    const store::StoreReader far("far/store", local.zarray_text(), local.zattrs_text(), 0,
                                 [&](glm::ivec3) { return damaged.bytes; });
    std::vector<std::byte> out(far.layout().brick_bytes());
    try {
        far.read_chunk({0, 1, 0}, out);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("far/store"), std::string::npos) << what;
        EXPECT_NE(what.find("0/0/1/0"), std::string::npos) << what;
    }
    // Asks the master cannot answer: past the store, past the octree, a store it does not have.
    EXPECT_THROW(answer_store_ask({StorePart::chunk, 1000}, &local, {}), WireError);
    EXPECT_THROW(answer_store_ask({StorePart::octree, 5}, &local, store::octree_file(path)),
                 WireError);
    EXPECT_THROW(answer_store_ask({StorePart::chunk, 0}, nullptr, {}), WireError);
}

TEST(StoreClient, AMasterThatDoesNotAnswerAndAnAnswerNobodyAskedForAreErrors) {
    const fs::path path = make_store(pattern_volume({40, 40, 40}), "remote_silent");
    const store::StoreReader local(path);
    InProcWorld world(2);
    std::thread master([&] { serve(*world.comm(0), &local, store::octree_file(path)); });
    auto comm = world.comm(1);
    {
        StoreClient opened(*comm, 30);  // the open's answers may take a while under sanitizers
        (void)opened.open("far", path.parent_path() / "cache");
    }
    send_message(*comm, 0, QuitMsg{});
    master.join();
    StoreClient remote(*comm, 0.3);
    // The master has stopped answering: the chunk's wait ends at the timeout, naming the chunk.
    try {
        remote.chunk({0, 0, 0});
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("0/0/0/0"), std::string::npos) << e.what();
    }
    EXPECT_THROW(remote.deliver(StorePartMsg{StorePart::chunk, 0, {}}), WireError);
    // Once the communication thread fails, every wait ends with its reason.
    remote.fail("rank 1: the master has stopped");
    try {
        remote.chunk({0, 0, 0});
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("the master has stopped"), std::string::npos);
    }
}

}  // namespace
}  // namespace isowall
