// Outputs appear whole or not at all: every output path checked before work, files staged under
// temporaries and committed together, temporaries gone on an error and on SIGINT/SIGTERM/SIGHUP.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>

#include "core/error.h"
#include "files/output_files.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> names_in(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
}

TEST(OutputFiles, EveryUnwritableTargetIsNamedBeforeAnyWork) {
    const auto dir = test::scratch_dir("output_problem");
    fs::create_directory(dir / "folder");
    std::ofstream(dir / "file.txt") << "x";
    struct Case {
        fs::path target;
        const char* mentions;  // empty: writable
    };
    const std::vector<Case> cases = {
        {dir / "ok.png", ""},
        {dir / "file.txt", ""},  // an existing file is replaced
        {"", "expected a file name"},
        {dir / "folder", "is a folder"},
        {dir / "no" / "such" / "x.png", "does not exist"},
        {dir / "file.txt" / "x.png", "is not a folder"},
        {"/dev/null", "not a regular file"},
        {"/proc/x.png", "cannot write in folder /proc"},
    };
    for (const Case& c : cases) {
        const std::string problem = output_problem(c.target);
        if (*c.mentions == 0) {
            EXPECT_EQ(problem, "") << c.target;
        } else {
            EXPECT_NE(problem.find(c.mentions), std::string::npos) << c.target << ": " << problem;
        }
    }
    EXPECT_EQ(names_in(dir), (std::vector<std::string>{"file.txt", "folder"}));
    try {
        check_output(dir / "folder", "--timeline");
        ADD_FAILURE() << "accepted a folder";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), (dir / "folder").string() +
                                             ": --timeline: is a folder; "
                                             "expected a file name");
    }
}

TEST(OutputFiles, AFolderWithoutWritePermissionIsRefused) {
    if (::geteuid() == 0) GTEST_SKIP() << "root writes anywhere; /proc stands in above";
    const auto dir = test::scratch_dir("output_readonly");
    fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_NE(output_problem(dir / "x.png").find("cannot write"), std::string::npos);
    fs::permissions(dir, fs::perms::owner_all);
}

TEST(OutputFiles, StagedFilesAppearTogetherAtCommit) {
    const auto dir = test::scratch_dir("output_commit");
    const std::size_t live = live_temporaries();
    {
        OutputFiles batch;
        for (const char* name : {"a.png", "b.csv"}) std::ofstream(batch.stage(dir / name)) << name;
        EXPECT_EQ(live_temporaries(), live + 2);
        EXPECT_FALSE(fs::exists(dir / "a.png"));
        for (const auto& n : names_in(dir)) EXPECT_EQ(n.rfind(".", 0), 0u) << n;  // hidden
        batch.commit();
    }
    EXPECT_EQ(names_in(dir), (std::vector<std::string>{"a.png", "b.csv"}));
    EXPECT_EQ(live_temporaries(), live);
}

TEST(OutputFiles, AnErrorBeforeCommitLeavesNothing) {
    const auto dir = test::scratch_dir("output_error");
    const std::size_t live = live_temporaries();
    try {
        OutputFiles batch;
        std::ofstream(batch.stage(dir / "a.png")) << "a";
        std::ofstream(batch.stage(dir / "b.png")) << "b";
        throw std::runtime_error("the replay failed");
    } catch (const std::runtime_error&) {
    }
    EXPECT_TRUE(names_in(dir).empty());
    EXPECT_EQ(live_temporaries(), live);
}

TEST(OutputFiles, AFailedRenameTakesBackTheBatch) {
    const auto dir = test::scratch_dir("output_rename");
    OutputFiles batch;
    std::ofstream(batch.stage(dir / "a.png")) << "a";
    std::ofstream(batch.stage(dir / "b.png")) << "b";
    // After the checks, b.png becomes a folder that is not empty: its rename must fail.
    fs::create_directories(dir / "b.png" / "inside");
    EXPECT_THROW(batch.commit(), std::runtime_error);
    EXPECT_FALSE(fs::exists(dir / "a.png"));
    EXPECT_EQ(names_in(dir), (std::vector<std::string>{"b.png"}));
}

// In a child: stage and write a file, then take `sig`. Returns the child's wait status.
int stage_then_signal(const fs::path& target, int sig, bool ignore_first) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        if (ignore_first) ::signal(sig, SIG_IGN);
        install_output_cleanup();
        OutputFiles batch;
        std::ofstream(batch.stage(target)) << "partial";
        ::raise(sig);
        ::_exit(7);  // reached only when the signal is ignored
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return status;
}

TEST(OutputFiles, ASignalRemovesTheTemporariesAndStillEndsTheProcess) {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
        const auto dir = test::scratch_dir("output_signal_" + std::to_string(sig));
        const int status = stage_then_signal(dir / "x.png", sig, false);
        EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "signal " << sig;
        EXPECT_TRUE(names_in(dir).empty()) << "signal " << sig << " left " << names_in(dir)[0];
    }
    // An ignored signal (nohup) stays ignored: the process goes on.
    const auto dir = test::scratch_dir("output_signal_ignored");
    const int status = stage_then_signal(dir / "x.png", SIGHUP, true);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 7);
}

}  // namespace
}  // namespace isowall
