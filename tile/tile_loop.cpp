#include "tile/tile_loop.h"

#include <chrono>
#include <cstdlib>
#include <thread>

#include "common/core/util.h"
#include "common/progressive/trace.h"
#include "tile/tile_inbox.h"

namespace isowall {
namespace {

// How long the communication thread waits for a message before it looks at its stop request.
constexpr double kReceivePollS = 0.05;

// The communication thread: every message from the master into the inbox, until quit (the last
// message a master sends a tile) or until told to end. A transport error or a malformed message
// closes the inbox with that error, so the frame thread reports it.
class Receiver {
  public:
    Receiver(Comm& comm, TileInbox& inbox)
        : comm_(comm), inbox_(inbox), thread_([this] { loop(); }) {}
    ~Receiver() {
        ending_ = true;
        thread_.join();
    }

  private:
    void loop() {
        try {
            while (!ending_) {
                auto e = comm_.receive(kMasterRank, kReceivePollS);
                if (!e) continue;
                Message m = decode_message(e->tag, e->bytes);
                const bool quit = std::holds_alternative<QuitMsg>(m);
                inbox_.push(std::move(m));
                if (quit) return;
            }
        } catch (...) {
            inbox_.close(std::current_exception());
        }
    }

    Comm& comm_;
    TileInbox& inbox_;
    std::atomic<bool> ending_{false};
    std::thread thread_;
};

class TileRank {
  public:
    TileRank(Comm& comm, TileSetup& setup)
        : comm_(comm),
          setup_(setup),
          sink_(setup.renderer),
          engine_(setup.extractor, setup.renderer, options()) {}

    int run() {
        send_message(comm_, kMasterRank, HelloMsg{comm_.host()});
        Receiver receiver(comm_, inbox_);
        for (;;) {
            trace_.switch_to(Stage::idle);
            std::optional<Message> m = inbox_.pop();
            trace_.switch_to(Stage::comm);
            // A view first, snapshots after: a request that came with the view is about that
            // view's frame (answered from it in flight), never about the frame before it, which
            // before the first view is the renderer's 16x16 warm-up.
            if (m && std::holds_alternative<ViewMsg>(*m)) {
                frame(std::get<ViewMsg>(*m));
            } else if (m && std::holds_alternative<QuitMsg>(*m)) {
                send_result();
                send_image();
                return 0;
            } else if (m) {
                throw WireError(std::string("a tile does not take ") + to_string(tag_of(*m)) +
                                " messages");
            }
            answer_snapshots();
        }
    }

  private:
    EngineOptions options() {
        EngineOptions opt = setup_.engine;
        opt.progress_interval_s = 0.05;
        opt.trace = &trace_;
        return opt;
    }

    void frame(const ViewMsg& v) {
        if (setup_.fault.kind == "hang") inbox_.wait_closed();
        if (setup_.fault.kind == "exit") std::_Exit(3);
        if (setup_.fault.kind == "throw") throw std::runtime_error("test fault: a tile throws");
        generation_ = v.generation;
        const double cpu0 = thread_cpu_seconds();
        FrameResult fr =
            engine_.run(v.view, v.region, sink_, inbox_.stop_flag(), [&](const TimelineSample& s) {
                const Stage left = trace_.switch_to(Stage::comm);
                send_message(comm_, kMasterRank,
                             ProgressMsg{generation_, s.rays, false, thread_cpu_seconds() - cpu0});
                answer_snapshots();
                trace_.switch_to(left);
            });
        result_.cpu_s += thread_cpu_seconds() - cpu0;
        result_.frame_s += fr.elapsed_s;
        ++result_.frames;
        result_.rays += fr.rays_cast;
        result_.groups += fr.group_count;
        result_.triangles = fr.timeline.empty() ? 0 : fr.timeline.back().triangles;
        trace_.switch_to(Stage::comm);
        if (fr.completed)
            send_message(comm_, kMasterRank,
                         ProgressMsg{generation_, fr.rays_cast, true, thread_cpu_seconds() - cpu0});
        else
            ++result_.interrupted;
    }

    void answer_snapshots() {
        for (int n = inbox_.take_snapshots(); n > 0; --n) send_image();
    }

    void send_image() {
        Image img;
        sink_.read_back(img);
        ImageMsg m;
        m.generation = generation_;
        m.width = img.width;
        m.height = img.height;
        m.rgba = std::move(img.rgba);
        send_message(comm_, kMasterRank, m);
    }

    void send_result() {
        result_.host = comm_.host();
        result_.rss_mib = current_rss_mib();
        trace_.close();
        result_.spans = trace_.spans();
        send_message(comm_, kMasterRank, result_);
    }

    Comm& comm_;
    TileSetup& setup_;
    TraceRecorder trace_;
    RendererSink sink_;
    ProgressiveEngine engine_;
    TileInbox inbox_;
    std::uint64_t generation_ = 0;
    TileResultMsg result_;
};

}  // namespace

int run_tile(Comm& comm, TileSetup& setup) {
    return TileRank(comm, setup).run();
}

}  // namespace isowall
