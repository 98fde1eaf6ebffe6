#pragma once
// TCP for `isowall serve` / `isowall view`, on asio: a connected stream (plain, or TLS once
// tls.h's handshake has run on it), whole sends, receives that wait at most a timeout, a connect
// with a timeout and a listener. Every failure is a NetError whose text names the peer
// ("127.0.0.1:5000") and what failed; the peer going away (EOF, reset, broken pipe) is a
// PeerClosed, so a server can tell a client that left from a fault.
//
// Every socket lives on one thread of the process (the net thread, net_stream.h); the calls here
// hand it their work and wait, so they may come from any thread: one reader, any number of
// senders (a send is whole, never interleaved with another) and shutdown_both() from anywhere,
// which wakes them all. Nothing waits without a bound except a send, which shutdown_both() ends.
// This header includes no asio: the rest of the program sees bytes and errors only.
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace isowall::remote {

struct NetError : std::runtime_error {
    using runtime_error::runtime_error;
};
// The peer closed the connection (EOF or reset), or this side shut it down.
struct PeerClosed : NetError {
    using NetError::NetError;
};

struct Stream;  // net_stream.h: the socket, its TLS session and what was read ahead

// A connected TCP stream, owned: the destructor closes it. Moved, never copied.
class Socket {
  public:
    Socket() = default;
    explicit Socket(std::shared_ptr<Stream> stream);
    ~Socket();
    Socket(Socket&&) noexcept = default;
    Socket& operator=(Socket&& other) noexcept;
    Socket(const Socket&) = delete;
    Socket& operator=(const Socket&) = delete;

    bool valid() const { return stream_ != nullptr; }
    void close();
    // Shuts both directions and cancels what waits: a receive, a send or a handshake on this
    // socket in another thread ends with PeerClosed, and so does every later call.
    void shutdown_both();
    // The descriptor, for reading the kernel's state of the connection (tcp_progress.h); -1 when
    // not valid. It stays open until the Socket is destroyed.
    int native_handle() const;
    // Waits at most `timeout_s` for the peer's first bytes and returns them without taking them
    // (the next receive, or tls.h's handshake, starts with them); nullopt when none came in time.
    // Throws PeerClosed when the peer closed before sending anything.
    std::optional<std::vector<std::byte>> peek(double timeout_s, const std::string& peer);
    // The end of a connection: TLS's close_notify, the sending side shut, then what the peer
    // still sends read and dropped (at most `max_bytes`, until it closes or `timeout_s` passes):
    // closing with unread bytes would reset the connection, and the reset can discard what was
    // just sent. Never throws.
    void finish(double timeout_s, std::size_t max_bytes);

    Stream* stream() const { return stream_.get(); }
    const std::shared_ptr<Stream>& shared_stream() const { return stream_; }

  private:
    std::shared_ptr<Stream> stream_;
};

// Sends every byte (through TLS when the socket has it). Throws PeerClosed (broken pipe, reset,
// shut down) or NetError, naming `peer`.
void send_all(const Socket& s, std::span<const std::byte> bytes, const std::string& peer);

// Reads what is there, at most buf.size() bytes, after waiting at most `timeout_s` for something
// to arrive; `got` is the count. false (got = 0) when nothing came in time; what arrives later
// waits for the next call. Throws PeerClosed on EOF, a reset or after shutdown_both(), NetError
// otherwise. A negative or infinite timeout waits forever.
bool recv_some(const Socket& s, std::span<std::byte> buf, double timeout_s, std::size_t& got,
               const std::string& peer);

// Connects to `host` (numeric IPv4 or IPv6, or a name) trying each address in turn within
// `timeout_s` in all. TCP_NODELAY is on (a request must not wait behind Nagle). NetError naming
// host:port and what failed: "127.0.0.1:5000: connect: Connection refused".
Socket connect_tcp(const std::string& host, int port, double timeout_s);

struct Acceptor;  // net_stream.h

class Listener {
  public:
    // Binds `address` (numeric, or a name; callers default to "127.0.0.1" so nothing is exposed
    // by accident) with SO_REUSEADDR, then listens. Port 0 takes an ephemeral port (tests; see
    // port()). NetError naming address:port: "127.0.0.1:5000: bind: Address already in use".
    static Listener open(const std::string& address, int port, int backlog = 16);

    Listener(Listener&&) noexcept = default;
    Listener& operator=(Listener&&) noexcept = default;
    ~Listener();

    int port() const { return port_; }  // the bound port, also after port 0
    const std::string& address() const { return address_; }
    bool valid() const { return acceptor_ != nullptr; }
    // The next connection, waiting at most `timeout_s`; nullopt when none came in time (one that
    // comes later waits for the next call). `peer`, when given, receives "ip:port" ("[::1]:40000"
    // for IPv6). TCP_NODELAY is on.
    std::optional<Socket> accept(double timeout_s, std::string* peer = nullptr);
    void close();

  private:
    Listener(std::shared_ptr<Acceptor> a, std::string address, int port);

    std::shared_ptr<Acceptor> acceptor_;
    std::string address_;
    int port_ = 0;
};

}  // namespace isowall::remote
