#pragma once
// One connection of the remote-viewing protocol: whole messages (view_framing.h) over a Socket.
//
// Threads: any number of senders (a mutex serialises whole messages, so the server's engine
// thread sending groups and its reader thread sending an error never interleave frames), one
// receiver at a time, and shutdown() from anywhere.
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "remote/net/socket.h"
#include "remote/net/token_bucket.h"
#include "remote/view_framing.h"

namespace isowall::remote {

// A paced send goes out in chunks of at most this many bytes, each waiting for its tokens: the
// dissertation's emulated link "added delays after sending each packet".
inline constexpr std::size_t kPaceChunkBytes = 16 * 1024;

// The clock that paces sends: seconds from any origin, and a wait. The default is steady_clock
// and a wait that shutdown() cuts short; tests put in a fake one whose wait only advances it.
struct PacingClock {
    std::function<double()> now_s;
    std::function<void(double seconds)> wait_s;
};

class Connection {
  public:
    Connection(Socket s, std::string peer,
               std::uint32_t max_payload_bytes = kDefaultMaxPayloadBytes);
    Connection(const Connection&) = delete;
    Connection& operator=(const Connection&) = delete;

    const std::string& peer() const { return peer_; }

    // Sends one whole message (header and payload), paced by the rate if one is set. Returns the
    // bytes sent, header included. Throws NetError, or PeerClosed (also when shutdown() ended a
    // paced wait), or WireError when the message cannot be framed.
    std::size_t send(const RemoteMessage& m);
    // The emulated link: `bits_per_second` > 0, or 0 for none (the default). Bytes already sent
    // are forgotten: the bucket starts full.
    void set_rate(double bits_per_second, std::size_t burst_bytes = kPaceChunkBytes);
    void set_pacing_clock(PacingClock clock);

    // The next whole message, waiting at most `timeout_s` in all; nullopt when none completed in
    // time (the bytes of a partial message stay buffered for the next call). Throws WireError
    // when the stream is broken (a bad header, a payload that does not decode: every later call
    // throws it again), or PeerClosed on EOF (saying so when the stream was cut short inside a
    // message) or after shutdown().
    std::optional<RemoteMessage> receive(double timeout_s);

    std::uint64_t bytes_sent() const { return bytes_sent_.load(); }
    std::uint64_t bytes_received() const { return bytes_received_.load(); }

    // Wakes a blocked receive (it then throws PeerClosed), a paced send's wait and a send blocked
    // on a full socket; later sends and receives throw PeerClosed. The socket stays open until
    // the Connection is destroyed, so another thread may still be using its descriptor.
    void shutdown();
    bool is_shut_down() const { return shut_down_.load(); }
    Socket& socket() { return socket_; }
    const Socket& socket() const { return socket_; }

  private:
    void pace(std::size_t bytes);  // waits until `bytes` may go, then takes them; send_mutex_ held
    [[noreturn]] void throw_shut_down() const;

    Socket socket_;  // plain, or TLS after a handshake on it (tls.h), before any message
    std::string peer_;
    FrameParser parser_;
    std::vector<std::byte> recv_buffer_;
    std::size_t recv_begin_ = 0, recv_end_ = 0;  // bytes recv gave that the parser has not taken

    std::mutex send_mutex_;
    TokenBucket bucket_;  // guarded by send_mutex_
    PacingClock clock_;   // guarded by send_mutex_
    std::mutex wake_mutex_;
    std::condition_variable wake_;       // a paced wait, woken by shutdown()
    std::optional<std::string> broken_;  // the WireError that broke the stream, if one did
    std::atomic<bool> shut_down_{false};
    std::atomic<std::uint64_t> bytes_sent_{0}, bytes_received_{0};
};

}  // namespace isowall::remote
