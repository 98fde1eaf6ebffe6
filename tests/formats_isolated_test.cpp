// Readers in a child process (readers/isolated_read.h): the volume comes back whole, an
// error as its line, and a child that crashes or hangs as one InputError naming the file.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "readers/isolated_read.h"
#include "readers/read_volume.h"
#include "tests/test_util.h"
#include "wire/wire.h"

namespace isowall {
namespace {
namespace fs = std::filesystem;

Volume sample_volume() {
    std::vector<std::byte> bytes(5 * 4 * 3 * 2);
    for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = std::byte(i * 7 + 1);
    Volume v({5, 4, 3}, VoxelType::i16, {0.5f, 0.75f, 2.0f}, std::move(bytes), "series");
    v.set_files({"/data/a.dcm", "/data/b.dcm"});
    Orientation o;
    o.axes = glm::mat3(0, 1, 0, -1, 0, 0, 0, 0, 1);
    o.origin = {-10.5f, 3.0f, 7.25f};
    o.known = true;
    v.set_orientation(o);
    v.add_fact("modality", "MR");
    v.add_fact("scaling", "value = 2 * stored + 1 (applied)");
    return v;
}

void expect_same_volume(const Volume& a, const Volume& b) {
    EXPECT_EQ(a.dims(), b.dims());
    EXPECT_EQ(a.type(), b.type());
    EXPECT_EQ(a.spacing(), b.spacing());
    EXPECT_EQ(a.source(), b.source());
    EXPECT_EQ(a.files(), b.files());
    EXPECT_EQ(a.orientation().axes, b.orientation().axes);
    EXPECT_EQ(a.orientation().origin, b.orientation().origin);
    EXPECT_EQ(a.orientation().known, b.orientation().known);
    ASSERT_EQ(a.facts().size(), b.facts().size());
    for (std::size_t i = 0; i < a.facts().size(); ++i) {
        EXPECT_EQ(a.facts()[i].name, b.facts()[i].name);
        EXPECT_EQ(a.facts()[i].value, b.facts()[i].value);
    }
    ASSERT_EQ(a.bytes().size(), b.bytes().size());
    EXPECT_TRUE(std::equal(a.bytes().begin(), a.bytes().end(), b.bytes().begin()));
}

TEST(IsolatedRead, TheHeaderRoundTripsAndAMalformedOneIsAWireError) {
    const Volume v = sample_volume();
    const std::vector<std::byte> header = formats::encode_volume_header(v);
    const fs::path file = test::scratch_dir("isolated_header") / "voxels";
    {
        std::ofstream out(file, std::ios::binary);
        const std::string pad(64, '\0');
        out.write(pad.data(), 64);
        out.write(reinterpret_cast<const char*>(v.bytes().data()),
                  std::streamsize(v.bytes().size()));
    }
    expect_same_volume(formats::decode_volume(header, MappedFile(file), 64), v);
    for (std::size_t cut : {std::size_t(1), header.size() / 2, header.size() - 1}) {
        const std::span<const std::byte> part(header.data(), cut);
        EXPECT_THROW(formats::decode_volume(part, MappedFile(file), 64), WireError) << cut;
    }
    // Voxels past the end of the file.
    EXPECT_THROW(formats::decode_volume(header, MappedFile(file), 128), std::runtime_error);
}

TEST(IsolatedRead, TheChildsVolumeComesBackWhole) {
    const Volume v = sample_volume();
    const pid_t parent = ::getpid();
    const Volume got = formats::read_isolated("series", "a test reader", [&] {
        EXPECT_NE(::getpid(), parent);  // (in the child: a failure here would not be seen)
        if (::getpid() == parent) throw std::logic_error("read in the parent");
        return sample_volume();
    });
    expect_same_volume(got, v);
    EXPECT_TRUE(got.mapped());
}

TEST(IsolatedRead, AnInputErrorComesBackAsItsLine) {
    try {
        formats::read_isolated("scan.h5", "a test reader", []() -> Volume {
            throw InputError("scan.h5", "dataset", "no dataset \"/v\" in the file");
        });
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), "scan.h5: dataset: no dataset \"/v\" in the file");
    }
    EXPECT_THROW(
        formats::read_isolated("scan.h5", "a test reader",
                               []() -> Volume { throw std::runtime_error("out of room"); }),
        std::runtime_error);
}

void expect_input_error(const std::function<Volume()>& read, const std::string& part,
                        std::chrono::milliseconds limit = formats::kIsolatedReadLimit) {
    try {
        formats::read_isolated("series/", "the DICOM decoder (GDCM)", read, limit);
        FAIL() << "no error";
    } catch (const InputError& e) {
        const std::string line = e.what();
        EXPECT_EQ(line.rfind("series/: data: the DICOM decoder (GDCM) ", 0), 0u) << line;
        EXPECT_NE(line.find(part), std::string::npos) << line;
        EXPECT_EQ(line.find('\n'), std::string::npos) << line;
    }
}

TEST(IsolatedRead, AChildThatCrashesOrHangsIsOneLine) {
    expect_input_error([]() -> Volume { std::abort(); }, "signal 6");
    expect_input_error([]() -> Volume { ::_exit(3); }, "exit status 3");
    const auto t0 = std::chrono::steady_clock::now();
    expect_input_error(
        []() -> Volume {
            std::this_thread::sleep_for(std::chrono::seconds(60));
            return sample_volume();
        },
        "did not finish within 1 s", std::chrono::milliseconds(1000));
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(30));
}

// A file the HDF5 fuzzer found to crash libhdf5 1.10 (a heap-buffer-overflow in H5VM_memcpyvv):
// through --volume's reader it is one line, whatever libhdf5 does with it. Under AddressSanitizer
// (CI's unit pass) the overflow ends the child, which must come back as one InputError; in a
// release build libhdf5 reads past its buffer unnoticed, and the read returns.
TEST(IsolatedRead, TheHdf5FuzzerFindingIsOneLine) {
    const fs::path crash =
        fs::path(ISOWALL_SOURCE_DIR) / "fuzz/regressions/hdf5/h5vm-memcpyvv-heap-overflow";
    ASSERT_TRUE(fs::exists(crash)) << crash;
    const fs::path copy = test::scratch_dir("isolated_hdf5") / "found.h5";
    fs::copy_file(crash, copy, fs::copy_options::overwrite_existing);
#if defined(__SANITIZE_ADDRESS__)
    const bool sanitized = true;
#else
    const bool sanitized = false;
#endif
    try {
        (void)formats::read_volume(copy.string(), std::nullopt);
        EXPECT_FALSE(sanitized) << "read under AddressSanitizer";
    } catch (const InputError& e) {
        const std::string line = e.what();
        EXPECT_EQ(line.rfind(copy.string() + ": data: the HDF5 library (libhdf5) failed", 0), 0u)
            << line;
        std::printf("%s\n", line.c_str());
    }
}

}  // namespace
}  // namespace isowall
