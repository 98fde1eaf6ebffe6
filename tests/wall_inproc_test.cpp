// The wall with every rank a thread of this process (comm/inproc_comm.h): the master's state
// machine and the tile loop are exercised in seconds, without mpirun. A 2x2 wall of small tiles on
// the phantom; each test runs five ranks: an interrupt mid-frame, a snapshot, a silent tile, and
// failures on either side, each ending every rank.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "app/wall_run.h"
#include "comm/inproc_comm.h"
#include "files/image_io.h"
#include "master/wall_report.h"
#include "progressive/trace.h"
#include "tests/image_compare.h"
#include "tests/test_util.h"
#include "wire/wire.h"

namespace isowall {
namespace {

struct WallRun {
    std::vector<int> codes;
    std::vector<TileResultMsg> results;
    std::string err;
    double seconds = 0;
};

WallOptions small_wall(const std::filesystem::path& dir) {
    std::ofstream(dir / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [80, 60]\n";
    WallOptions o;
    o.wall = (dir / "2x2.toml").string();
    o.out = (dir / "mosaic.png").string();
    o.volume.no_cache = true;
    return o;
}

WallRun run_wall_in_process(WallOptions o, int ranks = 5) {
    WallRun r;
    o.results_out = &r.results;
    testing::internal::CaptureStderr();
    const auto t0 = std::chrono::steady_clock::now();
    r.codes = run_in_process(ranks, [&](Comm& comm) { return run_wall(o, comm); });
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.err = testing::internal::GetCapturedStderr();
    return r;
}

std::filesystem::path write_script(const std::filesystem::path& dir, const std::string& text) {
    std::ofstream(dir / "script.txt") << text;
    return dir / "script.txt";
}

TEST(WallInProcess, OneFrameOnEveryTileAndAMosaic) {
    const auto dir = test::scratch_dir("inproc_one");
    const WallRun r = run_wall_in_process(small_wall(dir));
    for (int code : r.codes) EXPECT_EQ(code, 0) << r.err;
    ASSERT_EQ(r.results.size(), 5u);
    for (int rank = 1; rank <= 4; ++rank) {
        EXPECT_EQ(r.results[rank].frames, 1u) << "rank " << rank;
        EXPECT_GT(r.results[rank].rays, 0u) << "rank " << rank;
        EXPECT_FALSE(r.results[rank].spans.empty()) << "rank " << rank;
    }
    const Image mosaic = read_image(dir / "mosaic.png");
    EXPECT_EQ(mosaic.width, 160);
    EXPECT_EQ(mosaic.height, 120);
    std::printf("wall run: %.2f s\n", r.seconds);
}

TEST(WallInProcess, AChangeMidFrameInterruptsEveryTileAndTheMosaicIsTheLastView) {
    const auto dir = test::scratch_dir("inproc_interrupt");
    WallOptions o = small_wall(dir);
    // Every tile's engine pauses at each sample point (the `slow` test fault), so each view lasts
    // many progress messages whatever the machine's load, and a few rays into a view every tile
    // is inside a job of it (without the pause, a tile under a sanitizer on a loaded machine had
    // once cast all its jobs before the master saw the rays it waited for).
    o.fault = {FaultAction::slow, FaultMoment::none, TestFault::kEveryTile};
    o.script =
        write_script(dir, "wait rays 4\norbit 60 -20\nwait rays 4\niso 160\nwait done\n").string();
    const WallRun r = run_wall_in_process(o);
    for (int code : r.codes) EXPECT_EQ(code, 0) << r.err;
    ASSERT_EQ(r.results.size(), 5u);
    for (int rank = 1; rank <= 4; ++rank) {
        EXPECT_EQ(r.results[rank].frames, 3u) << "rank " << rank;
        EXPECT_GE(r.results[rank].interrupted, 1u) << "rank " << rank;
    }
    // The mosaic is the last view only: equal to the same wall run with that view from the start.
    WallOptions direct = small_wall(test::scratch_dir("inproc_interrupt_direct"));
    direct.script = write_script(dir, "orbit 60 -20\niso 160\nwait done\n").string();
    const WallRun d = run_wall_in_process(direct);
    for (int code : d.codes) ASSERT_EQ(code, 0) << d.err;
    const test::ImageComparison m =
        test::compare_images(read_image(dir / "mosaic.png"), read_image(direct.out));
    EXPECT_GE(m.mask_iou, 0.999) << m;
    EXPECT_GE(m.equal_share, 0.999) << m;
    std::printf("wall run: %.2f s\n", r.seconds);
}

// Every tile's engine pauses at each sample point (the `slow` test fault), so the frame lasts
// many progress messages whatever the machine's load: the snapshot asked for after the first
// one is answered in flight.
TEST(WallInProcess, ASnapshotMidFrameShowsTheFrameInFlight) {
    const auto dir = test::scratch_dir("inproc_snapshot");
    WallOptions o = small_wall(dir);
    o.fault = {FaultAction::slow, FaultMoment::none, TestFault::kEveryTile};
    o.script = write_script(dir, "iso 160\nwait rays 8\nsnapshot early\nwait done\nsnapshot late\n")
                   .string();
    const WallRun r = run_wall_in_process(o);
    for (int code : r.codes) EXPECT_EQ(code, 0) << r.err;
    const Image early = read_image(dir / "early.png");
    const Image late = read_image(dir / "late.png");
    const Image final_mosaic = read_image(dir / "mosaic.png");
    ASSERT_EQ(early.width, 160);
    ASSERT_EQ(early.height, 120);
    // After the frame completes, a snapshot is the final mosaic; before, it is a part of it.
    const test::ImageComparison done = test::compare_images(late, final_mosaic);
    EXPECT_EQ(done.differing_pixels, 0u) << done;
    // Groups only ever add to a frame, so every pixel the early snapshot shows stays covered.
    const test::ImageComparison part = test::compare_images(early, final_mosaic);
    const std::size_t covered_early = test::compare_images(early, early).covered_both;
    const std::size_t covered_final = test::compare_images(final_mosaic, final_mosaic).covered_both;
    EXPECT_GT(covered_early, 0u);
    EXPECT_EQ(part.covered_both, covered_early) << part;
    // In flight: a part, not the whole. Answered at the next sample point after the request, the
    // snapshot shows 68-76% of the final coverage here; answered only between jobs, 99.7%.
    EXPECT_LT(double(covered_early), 0.9 * double(covered_final)) << part;
    EXPECT_GT(part.differing_pixels, 0u) << part;
    std::printf("early snapshot: %zu covered pixels, final: %zu\n", covered_early, covered_final);
    std::printf("wall run: %.2f s\n", r.seconds);
}

// The master asks for a snapshot right after the first views: a tile may hold both before it
// starts its frame, and must answer from that frame (once it answered with its warm-up frame).
TEST(WallInProcess, ASnapshotAsTheFirstCommandShowsTheFirstFrame) {
    const auto dir = test::scratch_dir("inproc_first_snapshot");
    WallOptions o = small_wall(dir);
    o.script = write_script(dir, "snapshot first\nwait done\nsnapshot done\n").string();
    const WallRun r = run_wall_in_process(o);
    for (int code : r.codes) EXPECT_EQ(code, 0) << r.err;
    const Image first = read_image(dir / "first.png");
    EXPECT_EQ(first.width, 160);
    EXPECT_EQ(first.height, 120);
    const test::ImageComparison done =
        test::compare_images(read_image(dir / "done.png"), read_image(o.out));
    EXPECT_EQ(done.differing_pixels, 0u) << done;
}

// With --measure, `wait done` waits for every tile's curve of the frame as well; a frame with no
// job at all (the volume panned off the wall) is complete at once and its curves are asked for at
// once, so the wait ends instead of running into the timeout.
TEST(WallInProcess, MeasuredWaitsEndOnFramesWithAndWithoutJobs) {
    const auto dir = test::scratch_dir("inproc_measured_waits");
    WallOptions o = small_wall(dir);
    o.measure = true;
    o.timeout_s = 20;
    o.script = write_script(dir, "wait done\npan 10 0\nwait done\npan -10 0\nwait done\n").string();
    const WallRun r = run_wall_in_process(o);
    // A wait that ran into the timeout throws ("no tile rank has answered for 20 s") and ends
    // every rank with a non-zero code, so the codes tell it, not the wall clock (under ASan on a
    // loaded machine this run alone took 16 s).
    for (int code : r.codes) EXPECT_EQ(code, 0) << r.err;
    EXPECT_EQ(r.err.find("no tile rank has answered"), std::string::npos) << r.err;
    // Each tile kept the curve of every frame it finished before the last one.
    for (int rank = 1; rank <= 4; ++rank)
        EXPECT_EQ(r.results[static_cast<std::size_t>(rank)].earlier.size(), 2u) << "rank " << rank;
}

TEST(WallInProcess, ASilentTileIsNamedAfterTheTimeoutAndEveryRankEnds) {
    const auto dir = test::scratch_dir("inproc_silent");
    WallOptions o = small_wall(dir);
    o.timeout_s = 2;
    o.fault = {FaultAction::hang, FaultMoment::none, 2};
    const WallRun r = run_wall_in_process(o);
    for (int code : r.codes) EXPECT_NE(code, 0) << r.err;
    EXPECT_NE(r.err.find("isowall: error: rank 0 (master): no tile rank has answered for 2 s"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("waiting on rank 2 (tile 1)"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(o.out));
    std::printf("wall run: %.2f s\n", r.seconds);
}

// Whichever rank throws, tile or master, prints one line naming itself and every rank ends.
TEST(WallInProcess, ARankThatThrowsEndsEveryRankWithOneLine) {
    const struct {
        int rank;
        const char* line;
    } cases[] = {{3, "isowall: error: rank 3 (tile 2): test fault: a tile throws"},
                 {0, "isowall: error: rank 0 (master): test fault: the master throws"}};
    for (const auto& c : cases) {
        WallOptions o = small_wall(test::scratch_dir("inproc_throws_" + std::to_string(c.rank)));
        o.fault = {FaultAction::throw_error, FaultMoment::none, c.rank};
        const WallRun r = run_wall_in_process(o);
        for (int code : r.codes) EXPECT_NE(code, 0) << r.err;
        EXPECT_EQ(test::count_of(r.err, "isowall: error:"), 1u) << r.err;
        EXPECT_NE(r.err.find(c.line), std::string::npos) << r.err;
        EXPECT_FALSE(std::filesystem::exists(o.out));
        std::printf("wall run: %.2f s\n", r.seconds);
    }
}

// Every tile throws at its first view: the tiles tell the master, which prints the first it hears
// of, so the job still says why once, not once per tile.
TEST(WallInProcess, TilesThatFailTogetherGiveOneLine) {
    WallOptions o = small_wall(test::scratch_dir("inproc_tiles_throw"));
    o.fault = {FaultAction::throw_error, FaultMoment::none, TestFault::kEveryTile};
    const WallRun r = run_wall_in_process(o);
    for (int code : r.codes) EXPECT_NE(code, 0) << r.err;
    EXPECT_EQ(test::count_of(r.err, "isowall: error:"), 1u) << r.err;
    EXPECT_EQ(test::count_of(r.err, " (tile "), 1u) << r.err;
    EXPECT_NE(r.err.find("test fault: a tile throws"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(o.out));
}

// ---- the screen-region scheduler ------------------------------------------------------------

// A 2x2 wall of 640x480 tiles cut into 160x120 regions (16 per tile; large enough that a cell
// of the phantom projects to about a pixel: see the note in BalancedAndStaticMosaicsAreEqual).
// `one_tile`: the phantom zoomed out and panned into tile 0, so the other three tiles have nothing
// of their own to cast.
WallOptions balance_wall(const std::filesystem::path& dir, bool balance, bool one_tile) {
    std::ofstream(dir / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [640, 480]\n";
    WallOptions o;
    o.wall = (dir / "2x2.toml").string();
    o.out = (dir / "mosaic.png").string();
    o.volume.no_cache = true;
    o.balance = balance;
    o.region = "160x120";
    if (one_tile) {
        o.zoom = 0.45f;
        o.pan = {0.25f, -0.25f};
    }
    return o;
}

// The acceptance rule for two mosaics of one view: mask IoU >= 0.999 and >= 99.9% of pixels
// within 1/255.
test::ImageComparison expect_same_view(const std::string& a, const std::string& b) {
    test::CompareOptions within_one;
    within_one.channel_tolerance = 1;
    const test::ImageComparison m = test::compare_images(read_image(a), read_image(b), within_one);
    EXPECT_GE(m.mask_iou, 0.999) << m;
    EXPECT_GE(m.equal_share, 0.999) << m;
    return m;
}

std::uint64_t jobs_helped(const WallRun& r) {
    std::uint64_t n = 0;
    for (const TileResultMsg& t : r.results) n += t.jobs_helped;
    return n;
}

// Equal, not identical: a pixel whose own ray misses the surface may still be covered by a
// triangle of a cell extracted for a neighbouring pixel, and which neighbouring cells a run
// extracts depends on which rank cast which region. Where a cell projects below a pixel that is
// a few pixels in ten thousand of the silhouette and its small holes (at 320x240 tiles with the
// phantom zoomed out, 0.1-0.2% of the covered pixels; here about 0.02%). Static runs cut into
// regions but with no migration give the very same image as whole tiles.
TEST(WallBalance, BalancedAndStaticMosaicsAreEqual) {
    for (const bool one_tile : {true, false}) {
        SCOPED_TRACE(one_tile ? "surface inside one tile" : "surface over all tiles");
        const std::string name = one_tile ? "one" : "all";
        const WallOptions s =
            balance_wall(test::scratch_dir("balance_static_" + name), false, one_tile);
        WallOptions b = balance_wall(test::scratch_dir("balance_on_" + name), true, one_tile);
        b.region = "auto";  // the default: regions planned from the work, two frames of them
        // Jobs in emulated-time order (the earliest CPU clock first) must complete the frame and
        // give the same picture as well.
        b.dispatch = one_tile ? "emulated" : "arrival";
        b.measure = true;
        b.trace = (std::filesystem::path(b.out).parent_path() / "trace").string();
        const WallRun rs = run_wall_in_process(s);
        const WallRun rb = run_wall_in_process(b);
        for (int code : rs.codes) ASSERT_EQ(code, 0) << rs.err;
        for (int code : rb.codes) ASSERT_EQ(code, 0) << rb.err;
        EXPECT_EQ(jobs_helped(rs), 0u);
        EXPECT_GT(jobs_helped(rb), 0u) << "nothing migrated";
        for (int rank = 2; one_tile && rank <= 4; ++rank) {
            EXPECT_EQ(rs.results[static_cast<std::size_t>(rank)].rays, 0u)
                << "rank " << rank << " has surface of its own";
        }
        const test::ImageComparison m = expect_same_view(b.out, s.out);
        EXPECT_GT(m.covered_both, 1000u) << m;
        // Wall-wide correctness against emulated time rises to 1 once every job has landed.
        const std::vector<WallCurvePoint> curve = wall_curve(rb.results);
        ASSERT_FALSE(curve.empty());
        EXPECT_LT(curve.front().c, 1.0);
        EXPECT_DOUBLE_EQ(curve.back().final_pixels, 1.0);
        EXPECT_NEAR(curve.back().c, 1.0, 1e-9);
        EXPECT_GT(time_to(curve, 0.99, false), 0.0);
        // Each migrated job is a flow from its owner to the helper and back in the trace.
        std::ifstream json(b.trace + ".json");
        const std::string text((std::istreambuf_iterator<char>(json)), {});
        EXPECT_EQ(test::count_of(text, "\"ph\": \"s\""), 2 * jobs_helped(rb));
        EXPECT_EQ(
            test::count_of(text, "\"name\": \"region result\", \"cat\": \"job\", \"ph\": \"f\""),
            jobs_helped(rb));
        std::printf("%s: %llu jobs migrated; %s\n", name.c_str(),
                    (unsigned long long)jobs_helped(rb), testing::PrintToString(m).c_str());
    }
}

// Each rank on two engine threads (--threads 2; the in-process default is one per rank, five
// ranks sharing one machine): the mosaic of one thread per rank, with and without migration, and
// the ranks' traces carry the workers' CPU.
TEST(WallBalance, TwoThreadsPerRankGiveTheSameMosaic) {
    for (const bool balance : {false, true}) {
        SCOPED_TRACE(balance ? "balanced" : "static");
        const std::string name = balance ? "on" : "off";
        const WallOptions one =
            balance_wall(test::scratch_dir("threads_one_" + name), balance, false);
        WallOptions two = balance_wall(test::scratch_dir("threads_two_" + name), balance, false);
        two.threads = 2;
        const WallRun r1 = run_wall_in_process(one);
        const WallRun r2 = run_wall_in_process(two);
        for (int code : r1.codes) ASSERT_EQ(code, 0) << r1.err;
        for (int code : r2.codes) ASSERT_EQ(code, 0) << r2.err;
        const test::ImageComparison m = expect_same_view(two.out, one.out);
        EXPECT_GT(m.covered_both, 1000u) << m;
        double rays1 = 0, rays2 = 0;
        for (int rank = 1; rank <= 4; ++rank) {
            rays1 += static_cast<double>(r1.results[static_cast<std::size_t>(rank)].rays);
            rays2 += static_cast<double>(r2.results[static_cast<std::size_t>(rank)].rays);
        }
        // Static regions cast the same pixels on any number of threads (with migration, which
        // rank casts a region's band, and so which rays, depends on timing).
        if (!balance) {
            EXPECT_EQ(rays1, rays2);
        }
        std::printf("%s: %s\n", name.c_str(), testing::PrintToString(m).c_str());
    }
}

// A new view while helpers hold regions of the old one: their results, arriving late, are
// dropped, never composited into the new frame. The race is forced, not waited for: under the
// `late` test fault a helper that finishes a job of the first view tells the master and holds
// the result until the next view reaches it; the script changes the view once a helper has run
// a job (`wait helped 1`), so the first frame cannot end before the change. The surface is in
// tile 0 (rank 1), to which the master sends each view first: the in-process transport keeps
// each mailbox in order, so the owner has the new view before any held result comes.
TEST(WallBalance, AnInterruptWhileJobsMigrateLeavesNothingOfTheOldView) {
    const auto dir = test::scratch_dir("balance_interrupt");
    WallOptions o = balance_wall(dir, true, true);
    o.fault = {FaultAction::late, FaultMoment::none, TestFault::kEveryTile};
    o.script = write_script(dir, "wait helped 1\norbit 70 -30\nwait done\n").string();
    const WallRun r = run_wall_in_process(o);
    for (int code : r.codes) ASSERT_EQ(code, 0) << r.err;
    std::uint64_t dropped = 0;
    for (std::size_t rank = 1; rank < r.results.size(); ++rank) {
        const TileResultMsg& t = r.results[rank];
        if (rank == 1) {
            EXPECT_GT(t.jobs_own, 0u) << "the surface's tile";
        } else {
            EXPECT_EQ(t.late_dropped, 0u) << "rank " << rank << " owns no job";
        }
        dropped += t.late_dropped;
    }
    // Every held result was of the replaced view, and the owner dropped it.
    EXPECT_GE(dropped, 1u);
    WallOptions direct = balance_wall(test::scratch_dir("balance_interrupt_direct"), true, true);
    direct.script = write_script(dir, "orbit 70 -30\nwait done\n").string();
    const WallRun d = run_wall_in_process(direct);
    for (int code : d.codes) ASSERT_EQ(code, 0) << d.err;
    const test::ImageComparison m = expect_same_view(o.out, direct.out);
    std::printf("%llu late results dropped, %llu jobs migrated; %s\n", (unsigned long long)dropped,
                (unsigned long long)jobs_helped(r), testing::PrintToString(m).c_str());
}

// The wall-clock spans of one stage that some rank's span overlaps another rank's by more than
// `slack_s` (the ranks' traces: spans of the ranks' own frame threads).
int overlapping_spans(const std::vector<TileResultMsg>& results, Stage a, Stage b, double slack_s) {
    struct Span {
        double start, end;
        std::size_t rank;
    };
    std::vector<Span> spans;
    for (std::size_t rank = 1; rank < results.size(); ++rank)
        for (const TraceSpan& s : results[rank].spans)
            if (s.stage == static_cast<std::uint8_t>(a) || s.stage == static_cast<std::uint8_t>(b))
                spans.push_back({s.start_s, s.start_s + s.wall_s, rank});
    std::sort(spans.begin(), spans.end(),
              [](const Span& x, const Span& y) { return x.start < y.start; });
    std::vector<double> end_of(results.size(), -HUGE_VAL);  // each rank's latest end so far
    int overlaps = 0;
    for (const Span& s : spans) {
        for (std::size_t r = 1; r < end_of.size(); ++r)
            if (r != s.rank && end_of[r] > s.start + slack_s) {
                ++overlaps;
                break;
            }
        end_of[s.rank] = std::max(end_of[s.rank], s.end);
    }
    return overlaps;
}

// A wall emulated with one compute slot (--emulate-cores 1: one tile rank runs a job at a time)
// gives the mosaic of the wall without the limit, jobs still migrate, no two ranks' engines
// ever run at once (their traces' intersection and propagation spans never overlap), and the
// slots' name is gone from the host once the ranks end.
TEST(WallBalance, OneComputeSlotGivesTheSameMosaic) {
    const WallOptions plain = balance_wall(test::scratch_dir("slots_plain"), true, true);
    WallOptions one = balance_wall(test::scratch_dir("slots_one"), true, true);
    one.emulate_cores = 1;
    std::string job;
    WallRun r;
    r.codes = [&] {
        one.results_out = &r.results;
        testing::internal::CaptureStderr();
        auto codes = run_in_process(5, [&](Comm& comm) {
            if (comm.rank() == 0) job = comm.job_id();
            return run_wall(one, comm);
        });
        r.err = testing::internal::GetCapturedStderr();
        return codes;
    }();
    for (int code : r.codes) ASSERT_EQ(code, 0) << r.err;
    EXPECT_GT(jobs_helped(r), 0u);
    std::size_t spans = 0;
    for (const TileResultMsg& t : r.results) spans += t.spans.size();
    EXPECT_GT(spans, 100u);
    EXPECT_EQ(overlapping_spans(r.results, Stage::intersection, Stage::propagation, 1e-4), 0);
    EXPECT_FALSE(std::filesystem::exists("/dev/shm/sem.isowall-slots-" + job)) << job;
    const WallRun p = run_wall_in_process(plain);
    for (int code : p.codes) ASSERT_EQ(code, 0) << p.err;
    const test::ImageComparison m = expect_same_view(one.out, plain.out);
    EXPECT_GT(m.covered_both, 1000u) << m;
    std::printf("one slot: %d overlapping engine spans; without the limit: %d\n",
                overlapping_spans(r.results, Stage::intersection, Stage::propagation, 1e-4),
                overlapping_spans(p.results, Stage::intersection, Stage::propagation, 1e-4));
}

// A rank that speaks garbage: the master names it and the job ends, on every rank.
TEST(WallInProcess, AMalformedMessageToTheMasterEndsTheJobNamingTheRank) {
    const auto dir = test::scratch_dir("inproc_malformed");
    WallOptions o = small_wall(dir);
    testing::internal::CaptureStderr();
    const std::vector<int> codes = run_in_process(5, [&](Comm& comm) {
        if (comm.rank() != 4) return run_wall(o, comm);
        const std::byte junk[] = {std::byte{TileHelloMsg::kVersion}, std::byte{9}};  // cut short
        comm.send(kMasterRank, Tag::hello, junk);
        for (;;) comm.receive(-1, kForever);  // until the job ends
    });
    const std::string err = testing::internal::GetCapturedStderr();
    for (int code : codes) EXPECT_NE(code, 0) << err;
    EXPECT_NE(err.find("isowall: error: rank 0 (master): rank 4 (tile 3): hello message: "),
              std::string::npos)
        << err;
}

}  // namespace
}  // namespace isowall
