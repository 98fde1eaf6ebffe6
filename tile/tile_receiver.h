#pragma once
// A tile rank's communication thread (tile/tile_loop.h): every message for the rank into its
// inbox, so that the frame thread never waits in the transport.
#include <atomic>
#include <stdexcept>
#include <thread>

#include "comm/comm.h"
#include "tile/tile_inbox.h"
#include "wall_protocol/protocol.h"

namespace isowall {

class StoreClient;  // tile/store_client.h

// The communication thread: every message for this rank into the inbox, until release (the last
// message a master sends a tile) or until told to end. It tells the master it is alive every
// kAliveIntervalS, whatever the frame thread is doing. A transport error, a malformed message,
// one from a rank that may not send it, or a master silent for the timeout closes the inbox with
// that error, so the frame thread reports it.
class Receiver {
  public:
    Receiver(Comm& comm, TileInbox& inbox, double timeout_s, StoreClient* store);
    ~Receiver();
    // The CPU seconds this thread has used so far (its clock read from the frame thread; once
    // it has ended, its last reading).
    double cpu_s();

  private:
    void loop();
    double limit_s() const;
    MasterUnreachable silent_master() const;

    Comm& comm_;
    TileInbox& inbox_;
    double timeout_s_;
    StoreClient* store_;
    std::atomic<bool> ending_{false};
    std::atomic<double> final_cpu_s_{0};  // this thread's clock when it took the release or failed
    std::thread thread_;
};

}  // namespace isowall
