#pragma once
// TCP on POSIX sockets for `isowall serve` / `isowall view`: an owning Socket, whole
// sends, receives that wait at most a timeout, a connect with a timeout and a listener. Every
// failure is a NetError whose text names the peer ("127.0.0.1:5000") and the call that failed;
// the peer going away (EOF, reset, broken pipe) is a PeerClosed, so a server can tell a client
// that left from a fault. Nothing here blocks without a bound except send_all, which a
// shutdown_both() of the socket (from another thread) wakes.
#include <cstddef>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

namespace isowall::remote {

struct NetError : std::runtime_error {
    using runtime_error::runtime_error;
};
// The peer closed the connection (EOF or reset), or this side shut it down.
struct PeerClosed : NetError {
    using NetError::NetError;
};

// An owned file descriptor: closed by the destructor, moved but never copied.
class Socket {
  public:
    Socket() = default;
    explicit Socket(int fd) : fd_(fd) {}
    ~Socket() { close(); }
    Socket(Socket&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
    Socket& operator=(Socket&& other) noexcept;
    Socket(const Socket&) = delete;
    Socket& operator=(const Socket&) = delete;

    int fd() const { return fd_; }
    bool valid() const { return fd_ >= 0; }
    void close();
    // shutdown(SHUT_RDWR): a thread blocked in recv, poll or send on this socket wakes (recv sees
    // EOF). Safe to call from another thread while the socket is in use, unlike close().
    void shutdown_both();

  private:
    int fd_ = -1;
};

// Sends every byte (retrying partial sends and EINTR; MSG_NOSIGNAL, so a closed peer is an error,
// not a SIGPIPE). Throws PeerClosed (broken pipe, reset) or NetError, naming `peer`.
void send_all(const Socket& s, std::span<const std::byte> bytes, const std::string& peer);

// Reads what is there, at most buf.size() bytes, after waiting at most `timeout_s` (poll) for
// something to arrive; `got` is the count. false (got = 0) when nothing came in time. Throws
// PeerClosed on EOF or a reset, NetError otherwise. A negative or infinite timeout waits forever.
bool recv_some(const Socket& s, std::span<std::byte> buf, double timeout_s, std::size_t& got,
               const std::string& peer);

// Waits at most `timeout_s` (negative or infinite: for ever) until `s` can be read (or written,
// `for_write`), or has hung up or failed; false when the time ran out. The TLS layer waits here
// between its non-blocking reads and writes.
bool wait_ready(const Socket& s, bool for_write, double timeout_s, const std::string& peer);

// Connects to `host` (numeric IPv4 or IPv6, or a name for getaddrinfo) trying each address in
// turn, each within what is left of `timeout_s` (a non-blocking connect, then poll). The socket
// returned is blocking, with TCP_NODELAY on (a request must not wait behind Nagle). NetError
// naming host:port and what failed: "127.0.0.1:5000: connect: Connection refused".
Socket connect_tcp(const std::string& host, int port, double timeout_s);

class Listener {
  public:
    // Binds `address` (numeric, or a name; callers default to "127.0.0.1" so nothing is exposed
    // by accident) with SO_REUSEADDR, then listens. Port 0 takes an ephemeral port (tests; see
    // port()). NetError naming address:port: "127.0.0.1:5000: bind: Address already in use".
    static Listener open(const std::string& address, int port, int backlog = 16);

    int port() const { return port_; }  // the bound port, also after port 0
    const std::string& address() const { return address_; }
    bool valid() const { return socket_.valid(); }
    // The next connection, waiting at most `timeout_s`; nullopt when none came in time. `peer`,
    // when given, receives "ip:port" ("[::1]:40000" for IPv6). TCP_NODELAY is on.
    std::optional<Socket> accept(double timeout_s, std::string* peer = nullptr);
    void close() { socket_.close(); }

  private:
    Listener(Socket s, std::string address, int port)
        : socket_(std::move(s)), address_(std::move(address)), port_(port) {}

    Socket socket_;
    std::string address_;
    int port_ = 0;
};

}  // namespace isowall::remote
