// The isowall program on hostile volumes and volume options, by class: each is one error line
// naming the file or option and the field, a non-zero exit within the time limit, nothing written.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "tests/cli_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

using test::run_isowall;
using test::RunResult;
using test::slurp;

void write_bytes(const std::filesystem::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary) << bytes;
}

std::string floats(std::initializer_list<float> values, std::size_t count) {
    std::string out;
    for (std::size_t i = 0; i < count; ++i) {
        const float v = *(values.begin() + i % values.size());
        out.append(reinterpret_cast<const char*>(&v), sizeof v);
    }
    return out;
}

struct CliCase {
    const char* args;
    std::vector<std::string> mentions;
};

TEST(CliVolume, HostileVolumesAndOptionsAreOneLineEach) {
    const auto dir = test::scratch_dir("cli_volume");
    const std::string u8 = "NRRD0004\ntype: uchar\ndimension: 3\n";
    write_bytes(dir / "ok.raw", std::string(64, '\x01'));
    write_bytes(dir / "wrap.nhdr",
                u8 + "sizes: 4294967300 4 4\nencoding: raw\ndata file: ok.raw\n");
    write_bytes(dir / "ascii.nrrd",
                u8 + "sizes: 4 4 4\nencoding: ascii\n\n" + std::string(100000, '1'));
    write_bytes(dir / "nul.nrrd",
                u8 + "sizes: 4 4 4\nencoding: ascii\n\n" + std::string(100000, '\0'));
    write_bytes(dir / "zero.nhdr",
                u8 + "sizes: 4 4 4\nencoding: raw\nline skip: 1\ndata file: /dev/zero\n");
    write_bytes(dir / "nan.raw", floats({NAN, INFINITY, -INFINITY}, 64));
    const CliCase cases[] = {
        {"info -v ok.raw --dims 4 4 4 --type uint8 --header-bytes -8",
         {"--header-bytes", "\"-8\""}},
        {"info -v ok.raw --dims 4 4 4 --type uint8 --header-bytes 1.5", {"--header-bytes", "1.5"}},
        {"info -v ok.raw --dims 4 4 4 --type uint8 --header-bytes 99999999999999999999",
         {"--header-bytes"}},
        {"info -v ok.raw --dims 4 4 4 --type uint8 --header-bytes 18446744073709551615",
         {"--header-bytes", "9007199254740992"}},
        {"info -v wrap.nhdr", {"wrap.nhdr", "sizes", "4294967300"}},
        {"info -v ascii.nrrd", {"ascii.nrrd", "data", "64 characters"}},
        {"info -v nul.nrrd", {"nul.nrrd", "data", "\\x00"}},
        {"info -v zero.nhdr", {"zero.nhdr", "data file", "/dev/zero", "character device"}},
        {"extract -v nan.raw --dims 4 4 4 --type float32 --iso 0 --out s.ply",
         {"nan.raw", "data", "no finite voxel"}},
        {"render --huge-pages maybe --out s.png", {"--huge-pages", "maybe"}},
        // A C1 control (0x9B, a terminal's CSI) and a byte that is not UTF-8 in a file name
        // reach the terminal escaped.
        {"info -v \"$(printf '\\23331m\\377.nhdr')\"", {"\\x9B31m\\xFF.nhdr"}},
        {"render --huge-pages --out s.png", {"--huge-pages"}},
    };
    for (const CliCase& c : cases) {
        SCOPED_TRACE(c.args);
        const RunResult r = run_isowall(dir, c.args);
        EXPECT_NE(r.exit_code, 0);
        EXPECT_NE(r.exit_code, 124) << "timed out";
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_EQ(r.err.rfind("isowall: error: ", 0), 0u) << r.err;
        EXPECT_LT(r.err.size(), 400u) << r.err;
        for (const auto& m : c.mentions)
            EXPECT_NE(r.err.find(m), std::string::npos) << "missing \"" << m << "\" in: " << r.err;
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "s.ply"));
    EXPECT_FALSE(std::filesystem::exists(dir / "s.png"));
}

// --huge-pages on copies the phantom (any size) and says so; the picture is the mapped one's.
TEST(CliVolume, HugePagesOnGivesTheSameImage) {
    const auto dir = test::scratch_dir("cli_huge_pages");
    const auto render = [&](const std::string& mode) {
        std::string cmd = "cd '";
        cmd += dir.string();
        cmd += "' && '";
        cmd += ISOWALL_BINARY;
        cmd += "' render --size 160x120 --huge-pages ";
        cmd += mode + " --out " + mode + ".png > " + mode + ".txt";
        return std::system(cmd.c_str());
    };
    // The one reason to skip, checked positively: the kernel's THP setting is "never" (or the
    // kernel has none), and --huge-pages on then fails by design.
    const std::string thp = slurp("/sys/kernel/mm/transparent_hugepage/enabled");
    if (thp.empty() || thp.find("[never]") != std::string::npos)
        GTEST_SKIP() << "this kernel grants no transparent huge pages (THP setting: "
                     << (thp.empty() ? "absent" : thp) << ")";
    ASSERT_EQ(render("off"), 0);
    const int status = render("on");
    const std::string on = slurp(dir / "on.txt"), off = slurp(dir / "off.txt");
    ASSERT_EQ(status, 0) << "THP setting: " << thp << on;
    EXPECT_NE(on.find("in huge pages (--huge-pages on)"), std::string::npos) << on;
    EXPECT_NE(off.find("in memory (huge pages: no, --huge-pages off)"), std::string::npos) << off;
    EXPECT_EQ(slurp(dir / "on.png"), slurp(dir / "off.png"));
}

}  // namespace
}  // namespace isowall
