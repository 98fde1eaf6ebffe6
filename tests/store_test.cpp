// Volume stores (store/): the metadata, import, paging under a cap, and damaged stores.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <fstream>
#include <random>
#include <thread>

#include "core/error.h"
#include "core/number.h"
#include "extract/surface_extractor.h"
#include "store/open_store.h"
#include "store/store_writer.h"
#include "tests/store_test_util.h"
#include "tests/test_util.h"
#include "volume/phantom.h"

namespace isowall::store {
namespace {
namespace fs = std::filesystem;

using test::import_to;

using test::pattern_volume;

void expect_line(const std::function<void()>& f, std::initializer_list<std::string> mentions) {
    try {
        f();
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        for (const auto& m : mentions) EXPECT_NE(what.find(m), std::string::npos) << what;
    }
}

TEST(ByteSize, ByteSizesParseAndNonsenseDoesNot) {
    EXPECT_EQ(parse_byte_size("512M"), 512ull << 20);
    EXPECT_EQ(parse_byte_size("8G"), 8ull << 30);
    EXPECT_EQ(parse_byte_size("1.5GiB"), 3ull << 29);
    EXPECT_EQ(parse_byte_size("4096"), 4096u);
    EXPECT_EQ(parse_byte_size("64kb"), 64u << 10);
    for (const char* bad : {"", "M", "0", "-1G", "12X", "nan", "inf", "1e30T", "5 M", "0x100000000",
                            " 512M", "512M ", "+5G", "1e3M", "5.", "5.G", ".5G"})
        EXPECT_FALSE(parse_byte_size(bad)) << bad;
}

TEST(StoreFormat, BricksAre32UnlessThatMakesTooManyFiles) {
    const StoreLayout small = layout_for({100, 90, 80}, VoxelType::u8, glm::vec3(1));
    EXPECT_EQ(small.brick(), 32);
    EXPECT_EQ(small.grid(), glm::ivec3(4, 3, 3));  // edge bricks padded, as Zarr stores them
    EXPECT_EQ(small.brick_bytes(), std::size_t(32 * 32 * 32));
    const StoreLayout big = layout_for({2048, 2048, 2048}, VoxelType::f32, glm::vec3(1));
    EXPECT_EQ(big.brick(), 64);  // 32 would make 262,144 chunk files
    EXPECT_EQ(big.chunk_count(), std::size_t(32768));
    EXPECT_EQ(big.brick_bytes() % 4096, 0u);  // a page multiple: the pager copies whole pages
    for (std::size_t i : {std::size_t(0), std::size_t(5), std::size_t(35)})
        EXPECT_EQ(small.brick_index(small.brick_at(i)), i);
    EXPECT_EQ(chunk_key({3, 2, 1}), "0/1/2/3");
}

TEST(StoreFormat, BrickedViewIndexesEveryVoxelOnce) {
    VolumeView<std::uint8_t> v;
    v.dims = {37, 33, 34};
    v.bricks = 4;
    v.brick_grid = (v.dims + 15) >> 4;
    std::vector<std::uint8_t> seen(std::size_t(3 * 3 * 3) << 12, 0);
    for (int z = 0; z < v.dims.z; ++z)
        for (int y = 0; y < v.dims.y; ++y)
            for (int x = 0; x < v.dims.x; ++x) {
                const std::size_t i = v.index(x, y, z);
                ASSERT_LT(i, seen.size());
                EXPECT_EQ(seen[i]++, 0) << x << " " << y << " " << z;
            }
    // Brick (1, 0, 0) starts after the whole first brick; inside a brick, x is fastest.
    EXPECT_EQ(v.index(16, 0, 0), std::size_t(4096));
    EXPECT_EQ(v.index(1, 0, 0), std::size_t(1));
    EXPECT_EQ(v.index(0, 1, 0), std::size_t(16));
    EXPECT_EQ(v.index(0, 0, 1), std::size_t(256));
}

TEST(StoreFormat, MetadataRoundTripsAndNamesWhatIsWrong) {
    StoreLayout l = layout_for({33, 20, 17}, VoxelType::i16, {0.5f, 0.25f, 3.0f});
    l.value_min = -12;
    l.value_max = 900;
    l.source = "head.nrrd";
    l.id = new_store_id();
    const StoreLayout back = parse_layout(zarray_json(l), zattrs_json(l), "s");
    EXPECT_EQ(back.dims, l.dims);
    EXPECT_EQ(back.type, l.type);
    EXPECT_EQ(back.spacing, l.spacing);
    EXPECT_EQ(back.brick_log2, l.brick_log2);
    EXPECT_EQ(back.value_min, -12);
    EXPECT_EQ(back.value_max, 900);
    EXPECT_EQ(back.source, "head.nrrd");
    EXPECT_EQ(back.id, l.id);
    EXPECT_EQ(content_key(back), content_key(l));
    StoreLayout other = l;
    other.id = new_store_id();
    EXPECT_NE(content_key(other), content_key(l));  // a new import is new content
    for (VoxelType t : {VoxelType::u8, VoxelType::i8, VoxelType::u16, VoxelType::i16,
                        VoxelType::u32, VoxelType::i32, VoxelType::f32, VoxelType::f64})
        EXPECT_EQ(parse_zarr_dtype(zarr_dtype(t)), t);

    auto with = [&](std::string text, const std::string& from, const std::string& to) {
        const auto at = text.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        return text.replace(at, from.size(), to);
    };
    const std::string za = zarray_json(l), at = zattrs_json(l);
    expect_line([&] { parse_layout("{", at, "s"); }, {"s", "0/.zarray", "JSON"});
    expect_line([&] { parse_layout(with(za, "\"<i2\"", "\">i2\""), at, "s"); }, {"dtype"});
    expect_line([&] { parse_layout(with(za, "\"zstd\"", "\"blosc\""), at, "s"); }, {"compressor"});
    expect_line([&] { parse_layout(with(za, "32,", "24,"), at, "s"); }, {"chunks", "cubic"});
    // A member of the wrong type is the same one line, never nlohmann's type_error (fuzz_store
    // found it: "id": 1 in the compressor).
    expect_line([&] { parse_layout(with(za, "\"zstd\"", "1"), at, "s"); }, {"compressor"});
    expect_line([&] { parse_layout(with(za, "\"C\"", "[]"), at, "s"); }, {"order"});
    expect_line([&] { parse_layout(with(za, "\"/\"", "null"), at, "s"); }, {"dimension_separator"});
    expect_line([&] { parse_layout(za, with(at, "\"format\": 1", "\"format\": \"1\""), "s"); },
                {"isowall.format"});
    EXPECT_EQ(parse_layout(za, with(at, "\"head.nrrd\"", "7"), "s").source, "7");
    const std::string count = "\"chunks\": " + std::to_string(l.chunk_count());
    expect_line([&] { parse_layout(za, with(at, count, "\"chunks\": 7"), "s"); },
                {".zattrs", "isowall.chunks", "disagrees"});
    expect_line([&] { parse_layout(za, with(at, "\"format\": 1", "\"format\": 2"), "s"); },
                {"isowall.format"});
    expect_line([&] { parse_layout(za, with(at, l.id, "not-hex-at-all!!"), "s"); }, {"isowall.id"});
    expect_line(
        [&] { parse_layout(with(za, "\"zarr_format\": 2", "\"zarr_format\": 3"), at, "s"); },
        {"zarr_format"});
}

TEST(StoreImport, EveryVoxelComesBackUnderACapThatForcesEvictions) {
    if (const std::string why = paging_unavailable(); !why.empty())
        GTEST_SKIP() << "no paging here (" << why << "): a store is read whole";
    const Volume v = pattern_volume({300, 260, 200});
    const fs::path store = import_to(v, "store_pattern");
    EXPECT_TRUE(is_store(store));
    EXPECT_FALSE(fs::exists(temporary_for(store)));
    const StoreReader reader(store);
    const std::uint64_t cap = PagedVoxels::min_cap(reader.layout());
    ASSERT_LT(cap * 2, v.bytes().size()) << "the cap must be well under the volume";
    OpenedStore opened = open_store(store, cap);
    ASSERT_TRUE(opened.pager) << opened.how;
    const Volume& pv = opened.volume;
    EXPECT_EQ(pv.dims(), v.dims());
    EXPECT_EQ(pv.spacing(), v.spacing());
    EXPECT_TRUE(pv.paged());
    // Two threads, random voxels then a sweep: every voxel as imported.
    const auto a = v.view<std::uint16_t>(), b = pv.view<std::uint16_t>();
    ASSERT_TRUE(b.bricked());
    auto check = [&](unsigned seed, std::size_t* bad) {
        std::mt19937_64 rng(seed);
        for (int i = 0; i < 4000; ++i) {
            const int x = int(rng() % 300), y = int(rng() % 260), z = int(rng() % 200);
            if (a.at(x, y, z) != b.at(x, y, z)) ++*bad;
        }
    };
    std::size_t bad1 = 0, bad2 = 0;
    std::thread t1(check, 1u, &bad1), t2(check, 2u, &bad2);
    t1.join();
    t2.join();
    EXPECT_EQ(bad1 + bad2, 0u);
    // Brick by brick (a sweep in x rows would cross ten bricks a row and thrash a 16-brick cap).
    std::size_t bad = 0;
    for (int bz = 0; bz < 200; bz += 32)
        for (int by = 0; by < 260; by += 32)
            for (int bx = 0; bx < 300; bx += 32)
                for (int z = bz; z < std::min(bz + 32, 200); ++z)
                    for (int y = by; y < std::min(by + 32, 260); ++y)
                        for (int x = bx; x < std::min(bx + 32, 300); ++x)
                            bad += a.at(x, y, z) != b.at(x, y, z);
    EXPECT_EQ(bad, 0u);
    const PagingStats s = opened.pager->stats();
    EXPECT_GT(s.evictions, 0u);
    EXPECT_GT(s.refaults, 0u);
    EXPECT_LE(s.peak_bytes, cap);
    EXPECT_GE(s.faults, reader.layout().chunk_count());
}

TEST(StoreImport, TheSurfaceFromAPagedStoreIsTheSurfaceFromMemory) {
    if (const std::string why = paging_unavailable(); !why.empty())
        GTEST_SKIP() << "no paging here (" << why << "): a store is read whole";
    const Volume v = make_phantom({{260, 230, 210}, glm::vec3(1.0f)});
    const fs::path store = import_to(v, "store_phantom");
    const StoreReader reader(store);
    OpenedStore opened = open_store(store, PagedVoxels::min_cap(reader.layout()));
    const Mesh want = make_surface_extractor(v)->extract_full(kPhantomSkinIso);
    const Mesh got = make_surface_extractor(opened.volume)->extract_full(kPhantomSkinIso);
    ASSERT_GT(want.triangle_count(), 1000u);
    EXPECT_EQ(got.triangle_count(), want.triangle_count());
    EXPECT_EQ(got.positions, want.positions);
    EXPECT_GT(opened.pager->stats().evictions, 0u);
}

// A store keeps its octree beside its bricks, keyed by its content: moved, it still maps it.
TEST(StoreImport, TheOctreeLivesInTheStoreAndMovesWithIt) {
    const Volume v = make_phantom({{90, 80, 70}, glm::vec3(1.0f)});
    const fs::path store = import_to(v, "store_octree");
    auto extract_stats = [](const fs::path& at) {
        OpenedStore s = open_store(at, 64 << 20);
        OctreeSource src;
        src.volume_path = at;
        src.cache_dir = at.parent_path() / "unused-cache";
        OctreeStats st;
        (void)make_surface_extractor(s.volume, src, &st);
        return st;
    };
    // write_store built it from the slabs it read, node for node the octree of the whole volume.
    ASSERT_TRUE(fs::exists(octree_file(store)));
    const OctreeStats first = extract_stats(store);
    EXPECT_TRUE(first.from_cache) << first.cache_note;
    EXPECT_EQ(first.cache_file, octree_file(store));
    {
        OpenedStore s = open_store(store, 64 << 20);
        OctreeSource src;
        src.volume_path = store;
        src.own_file = octree_file(store);
        src.content_key = s.volume.content_key();
        const auto mapped =
            MinMaxOctree<std::uint8_t>::load_or_build(s.volume.view<std::uint8_t>(), src, nullptr);
        const auto whole = MinMaxOctree<std::uint8_t>::build(v.view<std::uint8_t>());
        ASSERT_EQ(mapped.nodes().size(), whole.nodes().size());
        EXPECT_TRUE(
            std::equal(mapped.nodes().begin(), mapped.nodes().end(), whole.nodes().begin()));
        EXPECT_EQ(mapped.finite_range().min, whole.finite_range().min);
        EXPECT_EQ(mapped.finite_range().max, whole.finite_range().max);
    }
    const fs::path moved = store.parent_path() / "moved.zarr";
    fs::rename(store, moved);
    const OctreeStats second = extract_stats(moved);
    EXPECT_TRUE(second.from_cache) << second.cache_note;
    EXPECT_EQ(second.cache_file, octree_file(moved));
    EXPECT_FALSE(fs::exists(store.parent_path() / "unused-cache"));
}

TEST(StoreImport, AnExistingStoreIsKeptUnlessReplacedAndNeverHalfWritten) {
    const Volume a = pattern_volume({40, 30, 20});
    const fs::path store = import_to(a, "store_replace");
    ImportOptions o;
    expect_line([&] { write_store(a, store, o); }, {"store", "--out", "--force"});
    const Volume b = make_phantom({{50, 40, 30}, glm::vec3(1.0f)});
    o.replace = true;
    write_store(b, store, o);
    EXPECT_EQ(StoreReader(store).layout().dims, glm::ivec3(50, 40, 30));
    EXPECT_FALSE(fs::exists(temporary_for(store)));
    // A folder that is not a store is never replaced.
    const fs::path other = store.parent_path() / "notes";
    fs::create_directories(other);
    expect_line([&] { write_store(b, other, o); }, {"notes", "not a store"});
    // What a stopped import left is cleared by the next one.
    fs::create_directories(temporary_for(store.parent_path() / "fresh") / "junk");
    write_store(b, store.parent_path() / "fresh", {});
    EXPECT_TRUE(is_store(store.parent_path() / "fresh"));
    EXPECT_FALSE(fs::exists(temporary_for(store.parent_path() / "fresh")));
}

// Two imports into one store at once: the second is refused while the first holds its
// temporary folder (here: at the moment the first is about to move its store into place), and the
// store that lands is the first's alone.
TEST(StoreImport, ASecondImportIntoTheSameStoreAtOnceIsRefused) {
    const fs::path store = test::scratch_dir("store_two_imports") / "store";
    const Volume a = pattern_volume({40, 30, 20});
    const Volume b = make_phantom({{50, 40, 30}, glm::vec3(1.0f)});
    ImportOptions first;
    bool second_ran = false;
    first.before_commit = [&](const StoreLayout&, const fs::path& tmp) {
        EXPECT_TRUE(fs::exists(tmp));
        expect_line([&] { write_store(b, store, {}); },
                    {"store", "--out", "another import is writing this store now",
                     ".store.importing is locked"});
        EXPECT_TRUE(fs::exists(tmp)) << "the refused import removed the first one's folder";
        second_ran = true;
    };
    write_store(a, store, first);
    EXPECT_TRUE(second_ran);
    EXPECT_EQ(StoreReader(store).layout().dims, glm::ivec3(40, 30, 20));
    EXPECT_FALSE(fs::exists(temporary_for(store)));
}

// --force replaces a store isowall wrote, and nothing else: a folder that only looks like one, or
// a store with the user's own files in it, is left alone, every file kept.
TEST(StoreImport, ForceReplacesOnlyAStoreIsowallWroteAndNothingInIt) {
    const Volume a = pattern_volume({40, 30, 20});
    const fs::path store = import_to(a, "store_force");
    const fs::path dir = store.parent_path();
    ImportOptions force;
    force.replace = true;
    // Looks like a store to a glance (.zattrs and 0/.zarray), holds the user's work.
    const fs::path lookalike = dir / "lookalike";
    fs::create_directories(lookalike / "0");
    std::ofstream(lookalike / ".zattrs") << "{}";
    std::ofstream(lookalike / "0" / ".zarray") << "{}";
    std::ofstream(lookalike / "thesis.tex") << "years of work";
    expect_line([&] { write_store(a, lookalike, force); },
                {"lookalike", "--out", "is not a store isowall wrote", "left alone"});
    EXPECT_TRUE(fs::exists(lookalike / "thesis.tex"));
    // A real store with a file of the user's beside its chunks.
    std::ofstream(store / "notes.txt") << "mine";
    expect_line([&] { write_store(a, store, force); },
                {"store", "--out", "holds \"notes.txt\", which is not part of a store"});
    EXPECT_TRUE(fs::exists(store / "notes.txt"));
    fs::remove(store / "notes.txt");
    write_store(make_phantom({{50, 40, 30}, glm::vec3(1.0f)}), store, force);
    EXPECT_EQ(StoreReader(store).layout().dims, glm::ivec3(50, 40, 30));
}

// A stop (a signal, app/stop_signals.h) ends the import at the next slab: no store, no temporary.
TEST(StoreImport, AStopEndsTheImportAndLeavesNothing) {
    const fs::path store = test::scratch_dir("store_stop") / "store";
    std::atomic<bool> stop{false};
    ImportOptions o;
    o.stop = &stop;
    int slabs = 0;
    o.progress = [&](const ImportProgress&) {
        ++slabs;
        stop = true;
    };
    try {
        write_store(make_phantom({{64, 64, 200}, glm::vec3(1.0f)}), store, o);
        ADD_FAILURE() << "the import was not stopped";
    } catch (const ImportStopped& e) {
        EXPECT_NE(std::string(e.what()).find("no store written"), std::string::npos);
    }
    EXPECT_EQ(slabs, 1);
    EXPECT_FALSE(fs::exists(store));
    EXPECT_FALSE(fs::exists(temporary_for(store)));
}

TEST(StoreDamage, AMissingChunkIsRefusedAtOpenNamingIt) {
    const fs::path store = import_to(pattern_volume({40, 300, 200}), "store_missing");
    const std::string key = chunk_key({1, 2, 0});
    fs::remove(store / key);
    expect_line([&] { StoreReader r(store); }, {store.string(), key, "missing"});
}

// A FIFO where a chunk belongs is named when the chunk is read (opening one to read would wait
// for a writer for ever); so is one where the metadata belongs.
TEST(StoreDamage, AFifoInPlaceOfAChunkOrItsMetadataIsNamedNotWaitedOn) {
    const fs::path store = import_to(pattern_volume({40, 300, 200}), "store_fifo");
    const std::string key = chunk_key({1, 2, 0});
    fs::remove(store / key);
    ASSERT_EQ(::mkfifo((store / key).c_str(), 0644), 0);
    const StoreReader r(store);
    std::vector<std::byte> out(r.layout().brick_bytes());
    expect_line([&] { r.read_chunk({1, 2, 0}, out); }, {store.string(), key, "not a file"});
    fs::remove(store / ".zattrs");
    ASSERT_EQ(::mkfifo((store / ".zattrs").c_str(), 0644), 0);
    expect_line([&] { StoreReader again(store); }, {store.string(), ".zattrs", "cannot read"});
}

TEST(StoreDamage, MetadataThatDisagreesWithTheChunksIsRefused) {
    const fs::path store = import_to(pattern_volume({40, 300, 200}), "store_disagree");
    StoreReader r(store);
    std::string za;
    {
        std::ifstream in(store / "0" / ".zarray");
        za.assign(std::istreambuf_iterator<char>(in), {});
    }
    // Bricks of 16 instead of 32: eight times the chunks the store holds.
    const auto at = za.find("32,");
    ASSERT_NE(at, std::string::npos);
    za.replace(at, 2, "16");
    const auto at2 = za.find("32,", at);
    ASSERT_NE(at2, std::string::npos);
    za.replace(at2, 2, "16");
    const auto at3 = za.find("32\n", at2);
    ASSERT_NE(at3, std::string::npos);
    za.replace(at3, 2, "16");
    std::ofstream(store / "0" / ".zarray") << za;
    // The chunk count no longer matches: refused at open.
    expect_line([&] { StoreReader again(store); }, {"isowall.chunks"});
}

// Opens `store`, reads the byte at `at` (paging its brick in), and exits 0 if the read returns.
[[noreturn]] void read_byte_and_exit(const fs::path& store, std::size_t at) {
    OpenedStore s = open_store(store, 64 << 20);
    volatile std::byte b = s.volume.bytes()[at];
    (void)b;
    std::_Exit(0);
}

// A damaged chunk found while a frame reads it ends the process with its line (paged_voxels.h).
TEST(StoreDamageDeathTest, ACorruptChunkEndsTheProcessNamingTheChunk) {
    if (const std::string why = paging_unavailable(); !why.empty())
        GTEST_SKIP() << "no paging here (" << why << "): a store is read whole";
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    const Volume v = pattern_volume({64, 128, 64});
    const fs::path store = import_to(v, "store_corrupt");
    const std::string key = chunk_key({1, 0, 0});
    {
        std::fstream f(store / key, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(40);
        const char junk[8] = {1, 2, 3, 4, 5, 6, 7, 8};
        f.write(junk, sizeof junk);
    }
    const StoreLayout l = StoreReader(store).layout();
    const std::size_t at = l.brick_bytes() + 5;  // a voxel of brick (1, 0, 0)
    EXPECT_EXIT(read_byte_and_exit(store, at), testing::ExitedWithCode(1), key);
    // Truncated: the same.
    fs::resize_file(store / key, 30);
    EXPECT_EXIT(read_byte_and_exit(store, at), testing::ExitedWithCode(1), key);
}

TEST(StoreDamage, ACapTooSmallForTheChunksIsOneLine) {
    if (const std::string why = paging_unavailable(); !why.empty())
        GTEST_SKIP() << "no paging here (" << why << "): a store is read whole";
    const fs::path store = import_to(pattern_volume({300, 260, 40}), "store_small_cap");
    expect_line([&] { open_store(store, 512 << 10); }, {"--memory-limit", "at least"});
}

}  // namespace
}  // namespace isowall::store
