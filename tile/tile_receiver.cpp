#include "tile/tile_receiver.h"

#include <pthread.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <string>

#include "core/util.h"
#include "tile/store_client.h"
#include "tile/tile_loop.h"
#include "wall_protocol/protocol.h"

namespace isowall {
namespace {

// How long the communication thread waits for a message before it looks at its stop request.
constexpr double kReceivePollS = 0.05;

}  // namespace

Receiver::Receiver(Comm& comm, TileInbox& inbox, double timeout_s, StoreClient* store)
    : comm_(comm), inbox_(inbox), timeout_s_(timeout_s), store_(store), thread_([this] {
          loop();
      }) {}

Receiver::~Receiver() {
    ending_ = true;
    thread_.join();
}

double Receiver::cpu_s() {
    clockid_t id;
    timespec ts{};
    if (pthread_getcpuclockid(thread_.native_handle(), &id) != 0 || clock_gettime(id, &ts) != 0)
        return final_cpu_s_;
    return std::max(final_cpu_s_.load(), double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec));
}

double Receiver::limit_s() const {
    return timeout_s_ + tile_grace_s(comm_.rank());
}

MasterUnreachable Receiver::silent_master() const {
    char msg[200];
    std::snprintf(msg, sizeof(msg),
                  "the master (rank 0) has sent nothing for %g s (--timeout): it has stopped, "
                  "or its host cannot be reached",
                  timeout_s_);
    return MasterUnreachable(msg);
}

void Receiver::loop() {
    try {
        Stopwatch alive_sent, master_heard, turn;
        bool master_gone = false;
        bool quit_seen = false;  // the master asked for this rank's result and image
        while (!ending_) {
            // A turn of this loop takes kReceivePollS; one far longer means this process was
            // stopped (SIGSTOP, a debugger) and has just been let go: the master is not the
            // one that went silent, so its clock starts again.
            if (turn.seconds() > timeout_s_ / 2) master_heard.restart();
            turn.restart();
            if (alive_sent.seconds() >= kAliveIntervalS) {
                send_message(comm_, kMasterRank, AliveMsg{});
                alive_sent.restart();
                // Where the job outlives a rank, mpirun does not end the tiles when the master
                // dies: one on this host is seen at once. What it sent before it ended (the
                // release, at the end of a wall that lost a rank) is taken first.
                master_gone = comm_.survives_rank_loss() && comm_.peer_gone(kMasterRank);
            }
            auto e = comm_.receive(-1, master_gone ? 0 : kReceivePollS);
            if (!e && master_gone && quit_seen) {
                // The master asked for this rank's outputs, got them and ended: its release may
                // not have reached this rank before its process went (a wall that lost a rank
                // ends without MPI_Finalize), so its end is the release.
                final_cpu_s_ = thread_cpu_seconds();
                inbox_.push(ReleaseMsg{});
                return;
            }
            if (!e && master_gone)
                throw MasterUnreachable(
                    "the master (rank 0) has ended: the wall cannot go on without it");
            if (!e) {
                if (master_heard.seconds() > limit_s()) throw silent_master();
                continue;
            }
            if (e->from == kMasterRank) master_heard.restart();
            Message m = decode_message(e->tag, e->bytes);
            if (std::holds_alternative<AliveMsg>(m) && e->from == kMasterRank) continue;
            if (auto* lost = std::get_if<LostMsg>(&m); lost && e->from == kMasterRank) {
                // Results for it in flight are dropped; stopped on this host, it is ended.
                comm_.forget(lost->rank);
                comm_.end_peer(lost->rank);
                continue;
            }
            if (auto* part = std::get_if<StorePartMsg>(&m); part && e->from == kMasterRank) {
                if (!store_)
                    throw WireError("a store_part message, and this rank reads its own store");
                store_->deliver(std::move(*part));
                continue;
            }
            // Region results come from helpers (tile ranks); everything else from the master.
            const bool from_helper = std::holds_alternative<RegionMsg>(m);
            if (from_helper == (e->from == kMasterRank))
                throw WireError(std::string("a ") + to_string(e->tag) + " message from rank " +
                                std::to_string(e->from) + ", which does not send them");
            const bool release = std::holds_alternative<ReleaseMsg>(m);
            quit_seen = quit_seen || std::holds_alternative<QuitMsg>(m);
            // This thread's clock cannot be read once it has ended, which may be before the
            // frame thread takes the release: its last reading is kept first.
            if (release) final_cpu_s_ = thread_cpu_seconds();
            inbox_.push(std::move(m));
            if (release) return;
        }
    } catch (const std::exception& e) {
        final_cpu_s_ = thread_cpu_seconds();
        // A pager waiting for a chunk would wait for nothing: it ends with this line.
        if (store_)
            store_->fail(std::string("rank ") + std::to_string(comm_.rank()) + ": " + e.what());
        inbox_.close(std::current_exception());
    } catch (...) {
        final_cpu_s_ = thread_cpu_seconds();
        if (store_) store_->fail("the communication thread ended");
        inbox_.close(std::current_exception());
    }
}

}  // namespace isowall
