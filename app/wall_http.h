#pragma once
// `isowall wall --http PORT`: the master serves a browser page (web/src/wall/) that shows the
// wall as a live mosaic of the tiles' previews (the control window's picture) and steers it.
// Every input on the page becomes a script line that runs through run_steering and
// WallMaster::execute (master/steering.h), beside the control window when --control is given.
// Several pages may watch; one steers at a time, and any may take over (master/wall_page.h).
//
// Threads: the WebServer's io thread takes the pages' messages into an inbox; the master's
// thread runs them (take), hands every page its state, and hands the tiles' previews to an
// encoder thread, which composes and compresses the mosaic (tens of milliseconds that would
// otherwise hold up the wall's jobs); the master's thread then gives each page the latest mosaic.
// Each page has a sender thread of its own, which keeps only the latest mosaic and state, so a
// slow page sees fewer pictures and never slows the wall or the other pages.
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/pacer.h"
#include "core/util.h"
#include "master/steering.h"
#include "master/wall_page.h"
#include "remote/http/web_server.h"
#include "remote/net/tls.h"
#include "wall_spec/control_layout.h"

namespace isowall {

struct WallHttpOptions {
    std::string address = "127.0.0.1";              // --http-listen
    int port = 0;                                   // --http (0: any free port, printed)
    std::string token;                              // --token: every page must present it
    std::shared_ptr<const remote::TlsContext> tls;  // https and wss; null: plain
    std::vector<std::string> allowed_hosts;         // --allow-host
    std::string out = "mosaic.png";                 // snapshots go beside it
    // The wall file's name as the pages show it: the name alone, not the master's folders, which
    // a page on another machine has no use for.
    std::string wall_name;
    std::size_t max_pages = 16;  // pages connected at once; more are turned away
};

// The page's files (web/dist/wall.html and what it loads) and the WebSocket /ws.
class WallHttp : public SteeringSource {
  public:
    // Listens at once (before the tiles load), so a port in use or an address off loopback
    // without TLS and --token ends the job before any frame (InputError naming --http or
    // --http-listen).
    WallHttp(const WallSpec& spec, WallHttpOptions options);
    ~WallHttp() override;
    WallHttp(const WallHttp&) = delete;
    WallHttp& operator=(const WallHttp&) = delete;

    int port() const { return web_->port(); }

    void begin() override;
    std::vector<SteeringLine> take(const WallMaster& master) override;
    void ran(const SteeringLine& line, const std::string& error) override;
    void show(const WallMaster& master, const FrameNote& frame, bool changed) override;

  private:
    // One connected page. Its sender thread sends `texts` in order, then the latest state and
    // mosaic, while the master's thread replaces them.
    struct Page {
        web::ConnectionId id = 0;
        std::string name;    // "page 3"
        bool hello = false;  // presented the token (master's thread only)
        std::mutex mutex;
        std::condition_variable wake;
        std::deque<std::string> texts;
        std::optional<std::string> state;
        std::shared_ptr<const std::string> mosaic;  // shared by every page
        std::optional<std::string> close_reason;    // close once the texts before it are sent
        std::atomic<bool> closed{false};
        std::thread sender;
    };
    struct Inbound {
        web::ConnectionId id;
        std::string bytes;
    };

    void opened(web::ConnectionId id, const std::string& peer);
    void message(web::ConnectionId id, std::string bytes, bool binary);
    void closed(web::ConnectionId id);
    void send_loop(Page& page);
    // Queues a text for one page; a page that lets kMaxQueuedTexts pile up is closed.
    void post(Page& page, std::string text);
    void handle(const std::shared_ptr<Page>& page, const std::string& bytes,
                std::vector<SteeringLine>& lines);
    void drop(const std::shared_ptr<Page>& page, const std::string& reason);
    std::string state_of(const WallMaster& master, const FrameNote& frame) const;
    // Every page that said hello.
    void broadcast(const std::string& text);

    WallHttpOptions o_;
    ControlLayout layout_;
    std::unique_ptr<web::WebServer> web_;
    // Master's thread only:
    SteeringSeat seat_;
    int next_snapshot_ = 1;
    std::vector<std::shared_ptr<Page>> roster_;       // the pages that said hello, in that order
    std::shared_ptr<const std::string> last_mosaic_;  // for a page that says hello
    PresentPacer pacer_;
    Stopwatch clock_, since_state_;
    bool roster_changed_ = false;
    std::uint64_t previews_seen_ = ~std::uint64_t{0};
    // The encoder thread and what it is given and gives back (guarded by encoder_mutex_).
    struct Pictures {
        std::vector<std::optional<PreviewMsg>> by_rank;
        std::uint64_t frame = 0;
    };
    void encode_loop();
    std::thread encoder_;
    std::mutex encoder_mutex_;
    std::condition_variable encoder_wake_;
    std::optional<Pictures> to_encode_;
    std::shared_ptr<const std::string> encoded_;
    bool encoder_stop_ = false, encoding_ = false;
    const WallSpec spec_;
    std::uint64_t mosaics_ = 0, made_bytes_ = 0;  // for the closing line (encoder's)
    double made_s_ = 0;
    // Guards what the io thread hands the master's thread.
    std::mutex mutex_;
    std::uint64_t next_page_ = 1;
    std::map<web::ConnectionId, std::shared_ptr<Page>> pages_;  // open connections
    std::vector<std::shared_ptr<Page>> gone_;                   // closed, sender to join
    std::vector<Inbound> inbox_;
};

}  // namespace isowall
