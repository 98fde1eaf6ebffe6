// The in-process transport keeps MPI's rules (order per sender, any-source receive, barrier) and
// ends every rank on abort; the tile inbox raises the stop flag for views and quit only.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <thread>

#include "comm/end_watch.h"
#include "comm/host_slots.h"
#include "comm/inproc_comm.h"
#include "tile/tile_inbox.h"

namespace isowall {
namespace {

std::vector<std::byte> bytes_of(std::uint8_t v) {
    return {std::byte{v}};
}

TEST(InProcComm, MessagesFromOneSenderArriveInOrderAndReceiveCanFilterBySource) {
    const auto codes = run_in_process(3, [](Comm& comm) {
        if (comm.rank() == 1)
            for (std::uint8_t i = 0; i < 10; ++i) comm.send(0, Tag::progress, bytes_of(i));
        if (comm.rank() == 2) comm.send(0, Tag::hello, bytes_of(99));
        if (comm.rank() != 0) return 0;
        auto from2 = comm.receive(2, kForever);
        if (!from2 || from2->from != 2 || from2->tag != Tag::hello) return 1;
        for (std::uint8_t i = 0; i < 10; ++i) {
            auto e = comm.receive(1, kForever);
            if (!e || e->bytes != bytes_of(i)) return 2;
        }
        return comm.receive(-1, 0.01) ? 3 : 0;  // nothing left: a timeout, not a block
    });
    EXPECT_EQ(codes, (std::vector<int>{0, 0, 0}));
}

TEST(InProcComm, BarrierWaitsForEveryRank) {
    std::atomic<int> arrived{0};
    const auto codes = run_in_process(4, [&](Comm& comm) {
        if (comm.rank() == 3) std::this_thread::sleep_for(std::chrono::milliseconds(50));
        ++arrived;
        comm.barrier();
        return arrived.load() == 4 ? 0 : 1;
    });
    EXPECT_EQ(codes, (std::vector<int>{0, 0, 0, 0}));
}

TEST(InProcComm, AbortWakesEveryBlockedRankWithItsCode) {
    const auto codes = run_in_process(3, [](Comm& comm) -> int {
        if (comm.rank() == 2) comm.abort(7);
        if (comm.rank() == 1) comm.barrier();
        comm.receive(-1, kForever);
        return 0;
    });
    EXPECT_EQ(codes, (std::vector<int>{7, 7, 7}));
}

TEST(InProcComm, AnEscapingExceptionAbortsTheWorld) {
    const auto codes = run_in_process(2, [](Comm& comm) -> int {
        if (comm.rank() == 1) throw std::runtime_error("boom");
        comm.receive(-1, kForever);
        return 0;
    });
    EXPECT_EQ(codes, (std::vector<int>{1, 1}));
}

TEST(InProcComm, EachWorldHasAJobIdOfItsOwnThatItsRanksShare) {
    InProcWorld a(2), b(2);
    EXPECT_EQ(a.comm(0)->job_id(), a.comm(1)->job_id());
    EXPECT_NE(a.comm(0)->job_id(), b.comm(0)->job_id());
}

// Two holders of a host's two slots leave none; a third waits, and gives up when its stop flag
// rises; a slot given back is taken again; a second opening of the job's name shares the count
// (another rank of the host), another job's name does not.
TEST(HostSlots, AtMostNHoldAtOnceAndAWaiterGivesUpOnStop) {
    InProcWorld world(1);
    const std::string job = world.id() + "-slots";
    HostSlots slots(job, 2);
    HostSlots same(job, 2);
    HostSlots other(job + "-other", 2);
    std::atomic<bool> stop{false};
    ASSERT_TRUE(slots.acquire(stop));
    ASSERT_TRUE(same.acquire(stop));
    EXPECT_EQ(slots.free_slots(), 0);
    EXPECT_EQ(other.free_slots(), 2);
    std::atomic<bool> gave_up{false};
    std::thread waiter([&] { gave_up = !slots.acquire(stop); });
    stop = true;
    waiter.join();
    EXPECT_TRUE(gave_up);
    stop = false;
    same.release();
    EXPECT_EQ(slots.free_slots(), 1);
    {
        const SlotHold hold(&slots, stop);
        EXPECT_TRUE(hold.ok());
        EXPECT_EQ(same.free_slots(), 0);
    }
    EXPECT_EQ(same.free_slots(), 1);
    slots.release();
    EXPECT_TRUE(slots.unlink());
    EXPECT_TRUE(same.unlink());  // already gone: no failure
    EXPECT_TRUE(other.unlink());
    EXPECT_TRUE(SlotHold(nullptr, stop).ok());  // no slots: no limit
}

TEST(HostSlots, NoSlotsIsRefused) {
    EXPECT_THROW(HostSlots("isowall-test-none", 0), std::runtime_error);
}

TEST(TileInbox, ViewsAndQuitRaiseStopSnapshotsDoNot) {
    TileInbox inbox;
    inbox.push(SnapshotMsg{});
    EXPECT_FALSE(inbox.stop_flag());
    EXPECT_FALSE(inbox.pop().has_value());  // only a snapshot request waits
    EXPECT_EQ(inbox.take_snapshots(), 1);
    inbox.push(ViewMsg{});
    EXPECT_TRUE(inbox.stop_flag());
    inbox.push(ViewMsg{});
    ASSERT_TRUE(inbox.pop().has_value());
    EXPECT_TRUE(inbox.stop_flag()) << "a second view is queued: the first frame must not run";
    ASSERT_TRUE(inbox.pop().has_value());
    EXPECT_FALSE(inbox.stop_flag());
    inbox.push(QuitMsg{});
    EXPECT_TRUE(inbox.stop_flag());
}

TEST(TileInbox, CloseWithAnErrorRethrowsItOnceTheQueueIsEmpty) {
    TileInbox inbox;
    inbox.push(ViewMsg{});
    inbox.close(std::make_exception_ptr(WireError("view message: truncated")));
    EXPECT_TRUE(inbox.stop_flag());
    EXPECT_TRUE(inbox.pop().has_value());
    EXPECT_THROW(inbox.pop(), WireError);
}

}  // namespace
}  // namespace isowall

// comm/end_watch.h: a process stopped after its watcher is armed is ended (SIGKILL) once the
// limit passes, with the line; one that is only stopped before the arming is left alone.
namespace isowall {
namespace {

// Runs `body` in a child process and returns how it ended (waitpid status) within `limit_s`,
// or -1 when it was still there (it is then killed).
int child_status(const std::function<void()>& body, double limit_s) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        body();
        ::_exit(0);
    }
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
    int status = 0;
    while (std::chrono::steady_clock::now() < end) {
        if (::waitpid(pid, &status, WNOHANG | WUNTRACED) == pid && !WIFSTOPPED(status))
            return status;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    return -1;
}

TEST(EndWatch, AStopAfterTheArmingIsEndedAfterTheLimit) {
    const int status = child_status(
        [] {
            EndWatch watch(0.3, "isowall: error: test rank stayed stopped\n");
            watch.arm();
            ::raise(SIGSTOP);
        },
        10);
    ASSERT_NE(status, -1) << "the stopped process was not ended";
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << status;
}

TEST(EndWatch, AnUnarmedWatchLetsAStoppedProcessBe) {
    const int status = child_status(
        [] {
            EndWatch watch(0.2, "isowall: error: should not print\n");
            ::raise(SIGSTOP);
        },
        1.5);
    EXPECT_EQ(status, -1) << "an unarmed watcher ended its process";
}

TEST(EndWatch, ProcessStoppedReadsTheState) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        for (;;) ::pause();
    }
    EXPECT_FALSE(process_stopped(pid));
    ::kill(pid, SIGSTOP);
    int status = 0;
    ::waitpid(pid, &status, WUNTRACED);
    EXPECT_TRUE(process_stopped(pid));
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    EXPECT_FALSE(process_stopped(pid)) << "a reaped process is not stopped";
}

}  // namespace
}  // namespace isowall
