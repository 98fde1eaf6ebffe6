// Every output option of the program against every way its path can be unwritable: one line
// naming the option before any work, and the folder as it was (no output, no temporary). A
// SIGTERM in the middle of a render leaves nothing behind either.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "tests/cli_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

namespace fs = std::filesystem;
using test::expect_one_line_error;
using test::files_in;
using test::run_isowall;

// How a path can be unwritable, and the path of that kind for an output named `name`.
enum class Kind { missing_folder, is_folder, unwritable, device };

// Makes the case in `dir` and returns the path to give the option.
std::string make_case(const fs::path& dir, Kind kind, const std::string& name) {
    switch (kind) {
        case Kind::missing_folder:
            return "no/such/" + name;
        case Kind::is_folder:
            fs::create_directories(dir / name / "inside");
            return name;
        case Kind::unwritable:
            fs::create_directory(dir / "ro");
            fs::permissions(dir / "ro", fs::perms::owner_read | fs::perms::owner_exec |
                                            fs::perms::others_read | fs::perms::others_exec);
            return "ro/" + name;
        case Kind::device:
            fs::create_symlink("/dev/null", dir / name);
            return name;
    }
    return name;
}

// Root writes anywhere: the unwritable case runs as nobody.
std::string prefix_for(Kind kind) {
    if (kind != Kind::unwritable || ::geteuid() != 0) return "";
    return "setpriv --reuid=65534 --regid=65534 --clear-groups ";
}

struct Output {
    std::string args;    // the command, with {} for the path (none: derived from --out)
    std::string option;  // the option its error names
    std::string name;    // the file name the case makes
    bool beside_out;     // derived from --out (snapshots): only its own name can be wrong
};

const std::vector<Output> kOutputs = {
    {"render --size 64x48 -q --out {}", "--out", "img.png", false},
    {"render --size 64x48 -q --depth-out {}", "--depth-out", "d.exr", false},
    {"render --size 64x48 -q --timeline {}", "--timeline", "t.csv", false},
    {"render --size 64x48 -q --out img.png --snapshots 90", "--snapshots", "img_final90.png", true},
    {"render --size 64x48 -q --out img.png --snapshot-rays 100", "--snapshot-rays", "img_r100.png",
     true},
    {"extract --iso 160 --out {}", "--out", "s.ply", false},
};

TEST(CliOutputs, EveryUnwritableOutputIsNamedBeforeAnyWorkAndLeavesNothing) {
    int tried = 0;
    for (const Output& o : kOutputs)
        for (Kind kind : {Kind::missing_folder, Kind::is_folder, Kind::unwritable, Kind::device}) {
            if (o.beside_out && (kind == Kind::missing_folder || kind == Kind::unwritable))
                continue;  // that is --out's folder, tried above
            const auto dir = test::scratch_dir("cli_outputs");
            fs::permissions(dir, fs::perms::all);  // nobody may create stdout.txt's neighbours
            const std::string path = make_case(dir, kind, o.name);
            const auto before = files_in(dir);
            std::string args = o.args;
            if (!o.beside_out) args.replace(args.find("{}"), 2, path);
            SCOPED_TRACE(args + " (" + std::to_string(int(kind)) + ")");
            const auto r = run_isowall(dir, args, prefix_for(kind));
            expect_one_line_error(r, {o.option});
            EXPECT_EQ(r.out, "") << "work started before the check";
            EXPECT_EQ(files_in(dir), before);
            if (fs::exists(dir / "ro")) {
                EXPECT_TRUE(fs::is_empty(dir / "ro"));
            }
            ++tried;
        }
    EXPECT_EQ(tried, 4 * 4 + 2 * 2);
}

TEST(CliOutputs, CollidingOrFormatlessOutputsAreRefused) {
    const auto dir = test::scratch_dir("cli_outputs_twice");
    // The image format is checked with the paths: this failed only after the whole render.
    for (const char* args : {"render --size 64x48 --out a.nosuchext",
                             "render --size 64x48 --out a.png --depth-out d.nosuchext"}) {
        const auto r = run_isowall(dir, args);
        expect_one_line_error(r, {"nosuchext", "no image format"});
        EXPECT_EQ(r.out, "") << "work started before the check";
    }
    expect_one_line_error(run_isowall(dir, "render --size 64x48 --out a.png --depth-out ./a.png"),
                          {"--depth-out", "--out"});
    expect_one_line_error(run_isowall(dir, "render --size 64x48 --out a.png --timeline a.png"),
                          {"--timeline", "--out"});
    EXPECT_TRUE(files_in(dir).empty());
}

// The brief's reproduction: --timeline /tmp wrote the image, then failed with a raw
// filesystem error. Now it fails first, and a good run writes every file or none.
TEST(CliOutputs, AllOutputsOfARenderAppearTogether) {
    const auto dir = test::scratch_dir("cli_outputs_together");
    expect_one_line_error(run_isowall(dir, "render --size 64x48 -o zz2.png --timeline /tmp"),
                          {"/tmp", "--timeline", "is a folder"});
    EXPECT_TRUE(files_in(dir).empty());
    const auto r = run_isowall(dir,
                               "render --size 64x48 -q -o a.png --depth-out a.exr --timeline "
                               "a.csv --snapshots 50,100 --snapshot-rays 10");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(files_in(dir), (std::vector<std::string>{"a.csv", "a.exr", "a.png", "a_final100.png",
                                                       "a_final50.png", "a_r10.png"}));
}

// Polls `dir` until a temporary (a hidden ".…tmp…" file) shows, for at most `limit`.
bool wait_for_temporary(const fs::path& dir, std::chrono::seconds limit) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < end) {
        for (const auto& name : files_in(dir))
            if (name.find(".tmp") != std::string::npos) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return false;
}

TEST(CliOutputs, SigtermMidRenderLeavesNoTemporary) {
    const auto dir = test::scratch_dir("cli_outputs_sigterm");
    const pid_t pid = ::fork();
    if (pid == 0) {
        if (::chdir(dir.c_str()) != 0) ::_exit(90);
        // The image is staged after the frame; the replay that follows takes a second or so.
        ::execl(ISOWALL_BINARY, "isowall", "render", "-q", "--size", "1600x1200", "-o", "big.png",
                "--snapshots", "90,99,99.9", static_cast<char*>(nullptr));
        ::_exit(91);
    }
    const bool seen = wait_for_temporary(dir, std::chrono::seconds(60));
    ::kill(pid, SIGTERM);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(seen) << "no temporary showed before the render ended";
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
    EXPECT_TRUE(files_in(dir).empty()) << files_in(dir)[0];
}

}  // namespace
}  // namespace isowall
