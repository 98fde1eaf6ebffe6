// The fault matrix (issue "Nothing hangs, nothing lies"): under mpirun, a 2x2 wall whose tile
// (rank 2) or master (rank 0) is killed (SIGKILL) or stopped (SIGSTOP) at each moment of a run:
// in MPI start-up, while loading, mid-frame, while it migrates a job, during the gather. Every
// case must end every rank within the limits plus a few seconds, name the rank that went (or, in
// MPI start-up, that a rank went), and leave no process and no output behind.
//
// The signal comes from the rank itself at the named moment (ISOWALL_TEST_FAULT=stop@frame:2),
// which is exact where an outside `kill` would race the run; the last test sends a real one from
// outside to a running wall.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <ostream>
#include <string>

#include "core/util.h"
#include "tests/run_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

using test::mpirun;
using test::run;
using test::slurp;

constexpr int kTimeoutS = 4;   // --timeout: silence of a running wall
constexpr int kStartupS = 10;  // --startup-timeout: MPI start-up, loading
constexpr int kGuardS = 90;    // the test's own limit on one run

struct Fault {
    const char* signal;  // "stop" or "kill"
    const char* moment;  // init, load, frame, migration, gather
    int rank;            // 2 (tile 1) or 0 (master)
};

std::string name_of(const Fault& f) {
    std::string s = f.signal;
    s += std::string("_") + f.moment + (f.rank == 0 ? "_master" : "_tile");
    return s;
}

void PrintTo(const Fault& f, std::ostream* os) {
    *os << f.signal << "@" << f.moment << ":" << f.rank;
}

// A killed rank between start-up and the end: by default mpirun sees the process end and ends
// every other rank before any could notice, so its own line would pass whatever isowall does.
// These rows run mpirun told not to (orte_abort_on_non_zero_status 0), so the line must be
// isowall's: its watchdogs name the dead rank as they name a silent one. Inside MPI_Init and at
// the end a dead rank leaves the others waiting in MPI itself (MPI_Init, MPI_Finalize), where no
// watchdog of ours ends them yet, so those rows keep mpirun's default and its line.
bool program_names_the_kill(const Fault& f) {
    const std::string moment = f.moment;
    return std::string(f.signal) == "kill" && moment != "init" && moment != "end";
}

// What the one line must say: who went silent (or, inside MPI start-up, where no rank can know
// which, that one did).
std::string expected_line(const Fault& f) {
    const std::string moment = f.moment;
    if (std::string(f.signal) == "kill" && !program_names_the_kill(f))
        return "mpirun noticed that process rank " + std::to_string(f.rank) + " with PID";
    if (moment == "init") return "MPI start-up did not finish within";
    if (moment == "end") return "stayed stopped for";  // its watcher's line (comm/end_watch.h)
    if (f.rank != 0) return "rank 2 (tile 1)";
    if (moment == "load") return "the master (rank 0) has not started the wall";
    return "the master (rank 0) has sent nothing for";
}

// The processes of a run: its folder is in every rank's command line.
bool any_process_of(const std::filesystem::path& dir) {
    const std::string cmd =
        "pgrep -f '[w]all --wall " + (dir / "2x2.toml").string() + "' >/dev/null";
    return std::system(cmd.c_str()) == 0;
}

// Files left in the run's folder other than its wall file and logs.
std::string outputs_in(const std::filesystem::path& dir) {
    std::string left;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
        const std::string name = e.path().filename().string();
        if (name != "2x2.toml" && name != "frames.txt" && name != "stop.sh" &&
            e.path().extension() != ".log")
            left += name + " ";
    }
    return left;
}

std::string wall_args(const std::filesystem::path& dir) {
    // The surface fills the top-right tile, so the other tiles help it (jobs migrate).
    return "wall --wall '" + (dir / "2x2.toml").string() + "' --out '" + (dir / "m.png").string() +
           "' --timeout " + std::to_string(kTimeoutS) + " --startup-timeout " +
           std::to_string(kStartupS) + " --zoom 0.5 --pan 0.25 -0.25";
}

// One run of the matrix: every rank ends in bounded time, the expected line names the rank, and
// no output is left.
void expect_the_job_ends_naming_the_rank(const Fault& f) {
    const auto dir = test::scratch_dir("fault_" + name_of(f));
    std::ofstream(dir / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [160, 120]\n";
    const std::string fault = std::string(f.signal) + "@" + f.moment + ":" + std::to_string(f.rank);
    Stopwatch took;
    const std::string keep_going =
        program_names_the_kill(f) ? "--mca orte_abort_on_non_zero_status 0 " : "";
    const int rc =
        run("env ISOWALL_TEST_FAULT=" + fault + " " + mpirun(5, keep_going) + wall_args(dir),
            dir / "run.log", kGuardS);
    const double seconds = took.seconds();
    const std::string log = slurp(dir / "run.log");
    std::printf("%s: exit %d after %.1f s\n", fault.c_str(), rc, seconds);
    EXPECT_NE(rc, 0) << log;
    EXPECT_NE(rc, 124) << "still running after " << kGuardS << " s: " << log;
    EXPECT_NE(log.find(expected_line(f)), std::string::npos) << log;
    const std::size_t lines = test::count_of(log, "isowall: error:");
    if (std::string(f.signal) == "stop") {
        // Inside MPI_Init no rank knows the others: the watchdogs are staggered by a second, and
        // a second rank may still speak before mpirun ends it.
        EXPECT_GE(lines, 1u) << log;
        EXPECT_LE(lines, std::string(f.moment) == "init" ? 2u : 1u) << log;
    } else if (program_names_the_kill(f)) {
        // Both tiles may notice a dead master in the same second; each line names it.
        EXPECT_GE(lines, 1u) << log;
        EXPECT_LE(lines, f.rank == 0 ? 2u : 1u) << log;
    } else {
        // mpirun ends the others at once; should one of them speak first, it names the dead rank.
        EXPECT_LE(lines, 1u) << log;
        if (lines == 1) {
            EXPECT_NE(log.find("rank " + std::to_string(f.rank)), std::string::npos) << log;
        }
    }
    EXPECT_FALSE(any_process_of(dir)) << "a rank outlived mpirun\n" << log;
    // At the end the outputs were written and said so before the stop ("wrote"); earlier, none.
    if (std::string(f.moment) == "end") {
        EXPECT_EQ(outputs_in(dir), "m.png ") << log;
        EXPECT_NE(log.find("wrote " + (dir / "m.png").string()), std::string::npos) << log;
    } else {
        EXPECT_EQ(outputs_in(dir), "") << log;
    }
}

std::vector<Fault> faults_of(const char* signal) {
    std::vector<Fault> faults;
    for (const char* moment : {"init", "load", "frame", "migration", "gather", "end"})
        for (int rank : {2, 0}) faults.push_back({signal, moment, rank});
    return faults;
}

std::string fault_name(const testing::TestParamInfo<Fault>& i) {
    return name_of(i.param);
}

// SIGSTOP: the rank is alive to MPI but silent; isowall's own watchdogs name it.
class FaultMatrix : public testing::TestWithParam<Fault> {};
TEST_P(FaultMatrix, EveryRankEndsIsowallNamingTheSilentRankAndNothingIsLeft) {
    expect_the_job_ends_naming_the_rank(GetParam());
}
INSTANTIATE_TEST_SUITE_P(Wall, FaultMatrix, testing::ValuesIn(faults_of("stop")), fault_name);

// SIGKILL: the process is gone. Between start-up and the end isowall's watchdogs name it (mpirun
// told not to end the job first); inside MPI_Init and at the end, mpirun names it and ends the
// rest (program_names_the_kill).
class FaultMatrixKill : public testing::TestWithParam<Fault> {};
TEST_P(FaultMatrixKill, EveryRankEndsTheDeadRankNamedAndNothingIsLeft) {
    expect_the_job_ends_naming_the_rank(GetParam());
}
INSTANTIATE_TEST_SUITE_P(Wall, FaultMatrixKill, testing::ValuesIn(faults_of("kill")), fault_name);

// An operator's `kill -STOP` from outside, at no moment the program chose: the wall is running a
// script of frames; once the master has printed its rank map, rank 2 is stopped by its pid.
TEST(FaultMatrix, AnOutsideStopOfARunningTileIsNamed) {
    const auto dir = test::scratch_dir("fault_outside_stop");
    std::ofstream(dir / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [160, 120]\n";
    std::ofstream script(dir / "frames.txt");
    for (int i = 0; i < 200; ++i) script << "orbit 3 0\nwait done\n";
    script.close();
    const std::string log = (dir / "run.log").string();
    // The rank's pid: the process of this run whose environment says OMPI_COMM_WORLD_RANK=2.
    std::ofstream(dir / "stop.sh")
        << mpirun(5) << wall_args(dir) << " --script '" << (dir / "frames.txt").string() << "' > '"
        << log << "' 2>&1 &\nm=$!\n"
        << "for i in $(seq 600); do grep -q '^wall:' '" << log << "' && break; sleep 0.1; done\n"
        << "for p in $(pgrep -f '[w]all --wall " << (dir / "2x2.toml").string() << "'); do\n"
        << "  tr '\\0' '\\n' < /proc/$p/environ 2>/dev/null | grep -qx OMPI_COMM_WORLD_RANK=2 &&"
        << " kill -STOP $p\ndone\nwait $m\n";
    Stopwatch took;
    const int rc = run("bash '" + (dir / "stop.sh").string() + "'", dir / "shell.log", kGuardS);
    const std::string text = slurp(log);
    std::printf("outside stop: exit %d after %.1f s\n", rc, took.seconds());
    EXPECT_NE(rc, 0) << text;
    EXPECT_NE(rc, 124) << text;
    // Named either as silent (no alive message) or as the rank the frame waits on, whichever
    // limit passes first: both run out --timeout after the stop.
    EXPECT_NE(text.find("rank 2 (tile 1)"), std::string::npos) << text;
    EXPECT_EQ(test::count_of(text, "isowall: error:"), 1u) << text;
    EXPECT_FALSE(any_process_of(dir)) << text;
    EXPECT_EQ(outputs_in(dir), "") << text;
}

}  // namespace
}  // namespace isowall
