#pragma once
// Inside remote/net/ only (socket.cpp, tls.cpp): the asio objects behind Socket and Listener, and
// the net thread that owns them.
//
// One io_context runs on one thread for the whole process, started by the first socket and never
// stopped (a socket may outlive any owner that could stop it). Every asio call on a socket or an
// acceptor runs on that thread, so none of them needs a strand or a lock; a caller posts its work
// there and waits on a Completion. A receive that runs out of time leaves its read pending, into
// the stream's own buffer, so no byte is lost and no caller's buffer is written after it left.
#include <asio.hpp>
#include <asio/ssl.hpp>

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace isowall::remote {

using NetClock = std::chrono::steady_clock;

// The process's io_context, its thread started on first use.
asio::io_context& net_context();

// A deadline `timeout_s` from now; nullopt (none) for a negative, infinite or huge timeout.
std::optional<NetClock::time_point> deadline_after(double timeout_s);

// One asynchronous operation's end, as the waiting caller sees it.
struct Completion {
    std::mutex mutex;
    std::condition_variable done_cv;
    bool done = false;
    asio::error_code error;
    std::size_t bytes = 0;

    void finish(const asio::error_code& e, std::size_t n);
    // Waits until done or the deadline; whether it is done.
    bool wait(std::optional<NetClock::time_point> deadline);
};

// Starts `start(handler)` on the net thread and waits for its end. When `deadline` passes first,
// `cancel` runs on the net thread and the wait goes on until the operation ends (cancelled
// operations end promptly); `timed_out` then says so. Returns the operation's error.
template <class Start, class Cancel>
asio::error_code run_on_net(Start start, Cancel cancel,
                            std::optional<NetClock::time_point> deadline, bool* timed_out = nullptr,
                            std::size_t* bytes = nullptr) {
    auto c = std::make_shared<Completion>();
    asio::post(net_context(), [c, start]() mutable {
        start([c](const asio::error_code& e, std::size_t n) { c->finish(e, n); });
    });
    const bool in_time = c->wait(deadline);
    if (!in_time) {
        asio::post(net_context(), cancel);
        c->wait(std::nullopt);
    }
    if (timed_out) *timed_out = !in_time;
    if (bytes) *bytes = c->bytes;
    return c->error;
}

using TlsStream = asio::ssl::stream<asio::ip::tcp::socket&>;

struct Stream : std::enable_shared_from_this<Stream> {
    explicit Stream(asio::ip::tcp::socket s);

    asio::ip::tcp::socket tcp;
    const int fd;                    // tcp's descriptor, fixed: read from any thread
    std::unique_ptr<TlsStream> tls;  // set by a handshake (tls.cpp); net thread only after it
    bool tls_closed = false;         // close_notify went out: read the plain socket from now on
    std::string tls_description;     // "TLSv1.3 TLS_AES_256_GCM_SHA384", set with `tls`

    std::mutex mutex;  // guards what follows, and what the net thread writes into `ahead`
    std::condition_variable read_cv;
    std::vector<std::byte> ahead;  // read ahead of the caller: [ahead_begin, ahead_end)
    std::size_t ahead_begin = 0, ahead_end = 0;
    bool reading = false;         // a read into `ahead` is pending on the net thread
    asio::error_code read_error;  // the error that ended the stream's reading; sticky
    bool shut = false;            // shutdown_both() was called

    std::mutex send_mutex;  // one whole send at a time

    // Starts a read into `ahead` on the net thread unless one is pending or bytes are waiting;
    // the mutex is held.
    void read_ahead_locked();
    // Waits (mutex held through `lock`) until bytes are waiting, the reading ended or the
    // deadline passed; whether bytes are waiting. Throws PeerClosed or NetError naming `peer`
    // when the reading ended with none.
    bool wait_ahead(std::unique_lock<std::mutex>& lock,
                    std::optional<NetClock::time_point> deadline, const std::string& peer);
    // Cancels what is pending on the socket and waits until no read is pending (net thread idle
    // for this stream); the mutex is not held.
    void cancel_and_settle();
};

// The error of a failed read or send as the exception it is: PeerClosed when the peer went away
// (EOF, reset, broken pipe, a TLS stream cut without close_notify) or this side shut down,
// NetError otherwise, naming `peer` and `what` ("recv", "send").
[[noreturn]] void throw_net_error(const asio::error_code& e, bool shut, const std::string& peer,
                                  const char* what);

// OpenSSL's reason for an error of asio's ssl category ("wrong version number"); "" for another.
std::string tls_reason(const asio::error_code& e);

struct Acceptor : std::enable_shared_from_this<Acceptor> {
    explicit Acceptor(asio::ip::tcp::acceptor a) : acceptor(std::move(a)) {}

    asio::ip::tcp::acceptor acceptor;
    std::mutex mutex;  // guards what follows
    std::condition_variable cv;
    bool accepting = false;  // an accept is pending on the net thread
    std::optional<asio::ip::tcp::socket> ready;
    asio::error_code error;  // a failure that ends accepting; sticky

    void accept_locked();  // starts an accept unless one is pending or a socket waits
};

}  // namespace isowall::remote
