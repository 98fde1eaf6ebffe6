// Streamed import's pieces (volume/plane_source.h, inflate_stream.h, nrrd_planes;
// readers/plane_stack.h, isolated_stream.h): planes decoded once each, in order, a slab
// held at a time; gzip inflated a piece at a time with decode_gzip's checks; a scaled stream's
// type chosen before its first voxel, and a value past the declared range refused; a child that
// fails mid-stream is one line; a store written from a stream equals one written from the volume.
#include <gtest/gtest.h>
#include <zlib.h>

#include <chrono>
#include <csignal>
#include <fstream>
#include <thread>

#include "core/error.h"
#include "readers/isolated_stream.h"
#include "readers/plane_stack.h"
#include "readers/read_volume.h"
#include "store/source_pages.h"
#include "store/store_format.h"
#include "store/store_writer.h"
#include "tests/formats_more_util.h"
#include "tests/plane_stream_util.h"
#include "tests/test_util.h"
#include "volume/inflate_stream.h"

namespace isowall {
namespace {

namespace fs = std::filesystem;

// A u16 volume whose voxels say where they are.
std::vector<std::byte> pattern(glm::ivec3 d) {
    std::vector<std::byte> b(std::size_t(d.x) * d.y * d.z * 2);
    auto* p = reinterpret_cast<std::uint16_t*>(b.data());
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) *p++ = std::uint16_t(x * 7 + y * 131 + z * 1031);
    return b;
}

// `bytes` as one gzip member.
std::string gzip_of(std::span<const std::byte> bytes) {
    z_stream z{};
    EXPECT_EQ(deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
    std::string out(deflateBound(&z, uLong(bytes.size())) + 32, '\0');
    z.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(bytes.data()));
    z.avail_in = uInt(bytes.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = uInt(out.size());
    EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
    out.resize(z.total_out);
    deflateEnd(&z);
    return out;
}

std::span<const std::byte> bytes_of(const std::string& s) {
    return std::as_bytes(std::span(s.data(), s.size()));
}

TEST(PlaneStream, EachPlaneIsDecodedOnceInOrderAndTheOverlapIsKept) {
    const glm::ivec3 dims{4, 3, 10};
    const std::vector<std::byte> all = pattern(dims);
    const std::size_t plane = 4 * 3 * 2;
    for (const bool ahead : {false, true}) {
        std::vector<std::pair<int, int>> calls;
        DecodedPlanes p(
            dims, VoxelType::u16, glm::vec3(1), "pattern",
            [&](int z0, int z1, std::byte* to) {
                calls.emplace_back(z0, z1);
                std::memcpy(to, all.data() + plane * std::size_t(z0), plane * std::size_t(z1 - z0));
            },
            ahead);
        for (auto [z0, z1] : {std::pair{0, 5}, {4, 9}, {8, 10}}) {
            const auto got = p.planes(z0, z1);
            ASSERT_EQ(std::memcmp(got.data(), all.data() + plane * std::size_t(z0), got.size()), 0)
                << z0;
        }
        // Read ahead: after planes 0-4, the next five (5-9) while the caller works on them.
        using Calls = std::vector<std::pair<int, int>>;
        const Calls want = ahead ? Calls{{0, 5}, {5, 10}} : Calls{{0, 5}, {5, 9}, {9, 10}};
        EXPECT_EQ(calls, want);
        EXPECT_EQ(p.peak_bytes(), (ahead ? 10 : 5) * plane);
        EXPECT_THROW(p.planes(2, 10), std::logic_error);  // back before the last call's start
    }
    // A decoder's error on the read-ahead thread comes out of the next call.
    DecodedPlanes failing(dims, VoxelType::u16, glm::vec3(1), "pattern",
                          [&](int z0, int, std::byte*) {
                              if (z0 > 0) throw InputError("pattern", "data", "slice 5 is damaged");
                          });
    failing.planes(0, 5);
    test::expect_input_error([&] { failing.planes(4, 9); }, "pattern", "data", "slice 5");
}

TEST(PlaneStream, GzipInflatesAPieceAtATimeWithItsChecks) {
    const std::vector<std::byte> all = pattern({16, 16, 8});
    const std::string packed = gzip_of(all);
    // Two members back to back, as gzip allows, read in uneven pieces.
    const std::string two =
        gzip_of(std::span(all).first(1000)) + gzip_of(std::span(all).subspan(1000));
    for (const std::string* in : {&packed, &two}) {
        InflateStream s(bytes_of(*in), all.size(), "v.raw.gz", "data");
        std::vector<std::byte> out(all.size());
        std::size_t at = 0;
        for (std::size_t step : {7u, 1000u, 513u}) {
            while (at + step <= out.size() / 2) s.read(out.data() + at, step), at += step;
        }
        s.read(out.data() + at, out.size() - at);
        EXPECT_EQ(out, all);
    }
    auto fails = [&](const std::string& in, std::uint64_t total, const std::string& words) {
        test::expect_input_error(
            [&] {
                InflateStream s(bytes_of(in), total, "v.raw.gz", "data");
                std::vector<std::byte> out(total);
                s.read(out.data(), out.size());
            },
            "v.raw.gz", "data", words);
    };
    fails(packed, all.size() + 1, "ends early");
    fails(packed, all.size() - 1, "exactly " + std::to_string(all.size() - 1));
    fails(packed + "tail", all.size(), "4 bytes follow");
    std::string damaged = packed;
    damaged[damaged.size() / 2] ^= 0x55;
    damaged[damaged.size() / 2 + 1] ^= 0x55;
    fails(damaged, all.size(), "");
}

void write(const fs::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
}

TEST(PlaneStream, GzipAndOtherEndianNrrdAndRawStreamAndHostOrderIsMapped) {
    const fs::path dir = test::scratch_dir("stream_nrrd");
    const glm::ivec3 dims{9, 7, 11};
    const std::vector<std::byte> all = pattern(dims);
    const std::string head = "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 9 7 11\n";
    write(dir / "gz.nrrd", head + "encoding: gzip\nendian: little\n\n" + gzip_of(all));
    std::vector<std::byte> big = all;
    swap_bytes(big, 2);
    write(dir / "big.nrrd", head + "encoding: raw\nendian: big\n\n" +
                                std::string(reinterpret_cast<const char*>(big.data()), big.size()));
    write(dir / "raw.nrrd", head + "encoding: raw\nendian: little\n\n" +
                                std::string(reinterpret_cast<const char*>(all.data()), all.size()));
    test::expect_streams_alike((dir / "gz.nrrd").string());
    test::expect_streams_alike((dir / "big.nrrd").string());
    test::expect_streams_alike((dir / "raw.nrrd").string(), false);
    // Headerless raw of the other byte order streams too (swapped a slab at a time); in host
    // order it is mapped.
    write(dir / "big.raw",
          "HEAD" + std::string(reinterpret_cast<const char*>(big.data()), big.size()));
    RawSpec spec;
    spec.dims = dims;
    spec.type = VoxelType::u16;
    spec.endian = Endian::big;
    spec.header_bytes = 4;
    const auto raw_stream = formats::open_planes((dir / "big.raw").string(), spec);
    ASSERT_TRUE(raw_stream);
    test::expect_planes_equal(*raw_stream, formats::read_volume((dir / "big.raw").string(), spec));
    spec.endian = Endian::little;
    EXPECT_FALSE(formats::open_planes((dir / "big.raw").string(), spec));
    // A gzip stream cut short fails on the slab that needs the missing bytes, naming the file.
    const std::string packed = gzip_of(all);
    write(dir / "cut.nrrd",
          head + "encoding: gzip\nendian: little\n\n" + packed.substr(0, packed.size() / 2));
    test::expect_input_error(
        [&] {
            auto p = nrrd_planes(dir / "cut.nrrd");
            for (int z = 0; z < dims.z; z += 4) p->planes(z, std::min(z + 4, dims.z));
        },
        (dir / "cut.nrrd").string(), "data", "ends early");
}

// A stack of u16 planes from `all`, with `scaling`, declaring `range`, mirrored when `mirror`.
formats::PlaneStack stack_of(const std::vector<std::byte>& all, glm::ivec3 dims,
                             formats::Scaling scaling,
                             std::optional<std::pair<double, double>> range, bool mirror = false) {
    formats::PlaneStack s;
    s.head.dims = dims;
    s.head.type = VoxelType::u16;
    s.head.scaling = scaling;
    s.head.format = "test";
    if (mirror) s.head.orientation.axes[0] = glm::vec3(-1, 0, 0);
    s.declared_range = range;
    const std::size_t plane = std::size_t(dims.x) * dims.y * 2;
    s.read = [all, plane](int z0, int z1, std::byte* to) {
        std::memcpy(to, all.data() + plane * std::size_t(z0), plane * std::size_t(z1 - z0));
    };
    return s;
}

TEST(PlaneStream, AScaledStreamTakesItsTypeFromTheDeclaredRangeAndHoldsItToIt) {
    const glm::ivec3 dims{6, 5, 9};
    std::vector<std::byte> all(std::size_t(dims.x) * dims.y * dims.z * 2);
    auto* v = reinterpret_cast<std::uint16_t*>(all.data());
    for (std::size_t i = 0; i < all.size() / 2; ++i) v[i] = std::uint16_t(i * 37 % 4096);
    // 12 bits stored, intercept -1024: a CT's Hounsfield units fit int16.
    const formats::Scaling ct{1, -1024};
    const Volume whole = formats::read_whole(stack_of(all, dims, ct, {{0, 4095}}, true), "ct");
    auto planes = formats::stream_planes(stack_of(all, dims, ct, {{0, 4095}}, true), "ct");
    EXPECT_EQ(planes->type(), VoxelType::i16);
    test::expect_planes_equal(*planes, whole);  // scaled and mirrored alike
    // Without a declared range, uint16's whole range scaled needs int32: the same values, wider.
    auto wide = formats::stream_planes(stack_of(all, dims, ct, std::nullopt), "ct");
    EXPECT_EQ(wide->type(), VoxelType::i32);
    // A value past the declared 12 bits would not fit the type chosen from them.
    v[all.size() / 2 - 1] = 5000;
    auto past = formats::stream_planes(stack_of(all, dims, ct, {{0, 4095}}), "ct");
    test::expect_input_error(
        [&] {
            for (int z = 0; z < dims.z; z += 4) past->planes(z, std::min(z + 4, dims.z));
        },
        "ct", "BitsStored", "5000");
    // A bad scaling is refused before any plane is read.
    test::expect_input_error(
        [&] {
            formats::stream_planes(stack_of(all, dims, {0, 1}, std::nullopt), "ct");
        },
        "ct", "scaling", "slope of 0");
}

TEST(PlaneStream, AChildThatFailsMidStreamIsOneLineAndADroppedStreamEndsIt) {
    const glm::ivec3 dims{8, 8, 40};
    const std::vector<std::byte> all = pattern(dims);
    auto failing_at = [&](int bad, int how) {
        return [&all, dims, bad, how] {
            formats::PlaneStack s = stack_of(all, dims, {}, std::nullopt);
            auto read = s.read;
            s.read = [read, bad, how](int z0, int z1, std::byte* to) {
                if (z1 > bad && how == 0)
                    throw InputError("scan.h5", "data", "slice 30 is damaged");
                if (z1 > bad && how == 1) std::abort();
                read(z0, z1, to);
            };
            return s;
        };
    };
    // Whole: the child's planes equal the stack's.
    auto good = formats::stream_isolated("scan.h5", "a test reader", failing_at(1000, 0));
    test::expect_planes_equal(*good, Volume(dims, VoxelType::u16, glm::vec3(1), all, "scan.h5"));
    auto read_all = [&](PlaneSource& p) {
        for (int z = 0; z < dims.z; z += 4) p.planes(z, std::min(z + 4, dims.z));
    };
    // The child reads 16 MiB at a time: these 40 planes are one read, which fails at once.
    test::expect_input_error(
        [&] { read_all(*formats::stream_isolated("scan.h5", "a test reader", failing_at(30, 0))); },
        "scan.h5", "data", "slice 30 is damaged");
    test::expect_input_error(
        [&] { read_all(*formats::stream_isolated("scan.h5", "a test reader", failing_at(30, 1))); },
        "scan.h5", "data", "signal 6");
    // A stream dropped after its first slab ends its child at once, even while its read-ahead
    // waits on the child: planes of 8 MiB, so the child hands over two at a time and then takes
    // 60 s for the next two.
    const glm::ivec3 big{2048, 2048, 6};
    const std::vector<std::byte> big_all = pattern(big);
    const auto t0 = std::chrono::steady_clock::now();
    {
        auto slow = formats::stream_isolated("scan.h5", "a test reader", [&] {
            formats::PlaneStack s = stack_of(big_all, big, {}, std::nullopt);
            auto read = s.read;
            s.read = [read](int z0, int z1, std::byte* to) {
                if (z0 >= 2) std::this_thread::sleep_for(std::chrono::seconds(60));
                read(z0, z1, to);
            };
            return s;
        });
        slow->planes(0, 2);  // and planes 2-3 are read ahead, from a child that sleeps
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(30));
}

// Every file of a store but its .zattrs (which holds the store's id), with its bytes; the octree
// from its nodes on (its 80-byte header's key holds the id too).
std::map<std::string, std::string> store_files(const fs::path& store) {
    std::map<std::string, std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(store)) {
        if (!e.is_regular_file() || e.path().filename() == ".zattrs") continue;
        std::ifstream in(e.path(), std::ios::binary);
        std::string bytes(std::istreambuf_iterator<char>(in), {});
        if (e.path().filename() == "octree.isowall") bytes = bytes.substr(80);
        out[fs::relative(e.path(), store).string()] = bytes;
    }
    return out;
}

TEST(PlaneStream, AStoreWrittenFromAStreamEqualsOneWrittenFromTheVolume) {
    const glm::ivec3 dims{70, 45, 150};  // slabs of bricks, the last one short
    const std::vector<std::byte> all = pattern(dims);
    const Volume v(dims, VoxelType::u16, {1.0f, 0.5f, 2.0f}, all, "pattern");
    const fs::path dir = test::scratch_dir("stream_store");
    store::ImportOptions o;
    o.threads = 2;
    store::write_store(v, dir / "from_volume", o);
    const std::size_t plane = std::size_t(dims.x) * dims.y * 2;
    DecodedPlanes planes(
        dims, VoxelType::u16, v.spacing(), "pattern", [&](int z0, int z1, std::byte* to) {
            std::memcpy(to, all.data() + plane * std::size_t(z0), plane * std::size_t(z1 - z0));
        });
    const store::ImportResult r = store::write_store(planes, dir / "from_stream", o);
    const auto a = store_files(dir / "from_volume"), b = store_files(dir / "from_stream");
    EXPECT_GT(a.size(), 40u);
    EXPECT_TRUE(a == b) << "the chunks, the levels or the octree differ";
    // Memory: a slab of bricks and the next plane, and as many read ahead; never the volume.
    EXPECT_LE(planes.peak_bytes(), 2 * plane * std::size_t(r.layout.brick() + 1));
    EXPECT_LT(planes.peak_bytes() * 2, all.size());
}

}  // namespace
}  // namespace isowall
