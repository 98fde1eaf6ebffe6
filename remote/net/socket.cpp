#include "remote/net/socket.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <sstream>

#include "remote/net/endpoint.h"

namespace isowall::remote {
namespace {

using Clock = std::chrono::steady_clock;

// "peer: what: strerror", as a PeerClosed when the error means the peer went away.
[[noreturn]] void throw_errno(const std::string& peer, const char* what, int err) {
    const std::string text = peer + ": " + what + ": " + std::strerror(err);
    if (err == EPIPE || err == ECONNRESET) throw PeerClosed(text);
    throw NetError(text);
}

// poll's timeout for what is left until `deadline` (-1 = forever), rounded up so that a wait
// never ends before its deadline.
int poll_ms(std::optional<Clock::time_point> deadline) {
    if (!deadline) return -1;
    const auto left = *deadline - Clock::now();
    if (left <= Clock::duration::zero()) return 0;
    const auto ms = std::chrono::ceil<std::chrono::milliseconds>(left).count();
    return ms > 1'000'000'000 ? 1'000'000'000 : static_cast<int>(ms);
}

std::optional<Clock::time_point> deadline_after(double timeout_s) {
    if (!(timeout_s >= 0) || std::isinf(timeout_s) || timeout_s > 1e9) return std::nullopt;
    return Clock::now() +
           std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
}

// Waits for `events` on `fd` until `deadline`: the revents, or 0 when the time ran out.
short wait_for(int fd, short events, std::optional<Clock::time_point> deadline,
               const std::string& peer) {
    for (;;) {
        pollfd p{fd, events, 0};
        const int n = ::poll(&p, 1, poll_ms(deadline));
        if (n > 0) return p.revents;
        if (n == 0) {
            if (!deadline || Clock::now() >= *deadline) return 0;
            continue;  // poll's millisecond rounding woke us a little early
        }
        if (errno != EINTR) throw_errno(peer, "poll", errno);
    }
}

void set_nodelay(int fd) {
    const int on = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);  // only latency if it fails
}

struct AddrInfoFree {
    void operator()(addrinfo* a) const { ::freeaddrinfo(a); }
};
using AddrInfo = std::unique_ptr<addrinfo, AddrInfoFree>;

AddrInfo resolve(const std::string& host, int port, int flags, const std::string& peer) {
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = flags | AI_NUMERICSERV;
    addrinfo* out = nullptr;
    const int rc = ::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &out);
    if (rc != 0) {
        throw NetError(
            peer + ": resolve: " + (rc == EAI_SYSTEM ? std::strerror(errno) : ::gai_strerror(rc)));
    }
    return AddrInfo(out);
}

std::string numeric_peer(const sockaddr* addr, socklen_t len) {
    char host[NI_MAXHOST], serv[NI_MAXSERV];
    if (::getnameinfo(addr, len, host, sizeof host, serv, sizeof serv,
                      NI_NUMERICHOST | NI_NUMERICSERV) != 0)
        return "unknown peer";
    return host_port(host, std::atoi(serv));
}

// One address of connect_tcp: a connected blocking socket, or the errno of the failure (0 with
// no socket when the deadline passed).
Socket connect_one(const addrinfo& a, std::optional<Clock::time_point> deadline,
                   const std::string& peer, int& err) {
    Socket s(::socket(a.ai_family, a.ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, a.ai_protocol));
    if (!s.valid()) {
        err = errno;
        return {};
    }
    if (::connect(s.fd(), a.ai_addr, a.ai_addrlen) != 0) {
        if (errno != EINPROGRESS && errno != EINTR) {
            err = errno;
            return {};
        }
        if (wait_for(s.fd(), POLLOUT, deadline, peer) == 0) {
            err = 0;
            return {};
        }
        socklen_t len = sizeof err;
        if (::getsockopt(s.fd(), SOL_SOCKET, SO_ERROR, &err, &len) != 0) err = errno;
        if (err != 0) return {};
    }
    const int flags = ::fcntl(s.fd(), F_GETFL);
    if (flags < 0 || ::fcntl(s.fd(), F_SETFL, flags & ~O_NONBLOCK) != 0) {
        err = errno;
        return {};
    }
    set_nodelay(s.fd());
    return s;
}

}  // namespace

Socket& Socket::operator=(Socket&& other) noexcept {
    if (this != &other) {
        close();
        fd_ = other.fd_;
        other.fd_ = -1;
    }
    return *this;
}

void Socket::close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
}

void Socket::shutdown_both() {
    if (fd_ >= 0) ::shutdown(fd_, SHUT_RDWR);  // ENOTCONN (never connected, already shut): fine
}

void send_all(const Socket& s, std::span<const std::byte> bytes, const std::string& peer) {
    while (!bytes.empty()) {
        const ssize_t n = ::send(s.fd(), bytes.data(), bytes.size(), MSG_NOSIGNAL);
        if (n > 0) {
            bytes = bytes.subspan(static_cast<std::size_t>(n));
        } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            wait_for(s.fd(), POLLOUT, std::nullopt, peer);  // a non-blocking socket: wait for room
        } else if (n < 0 && errno != EINTR) {
            throw_errno(peer, "send", errno);
        }
    }
}

bool recv_some(const Socket& s, std::span<std::byte> buf, double timeout_s, std::size_t& got,
               const std::string& peer) {
    got = 0;
    const auto deadline = deadline_after(timeout_s);
    for (;;) {
        if (wait_for(s.fd(), POLLIN, deadline, peer) == 0) return false;
        // MSG_DONTWAIT: poll said readable, but never block past the deadline if it was wrong.
        const ssize_t n = ::recv(s.fd(), buf.data(), buf.size(), MSG_DONTWAIT);
        if (n > 0) {
            got = static_cast<std::size_t>(n);
            return true;
        }
        if (n == 0) {
            if (buf.empty()) return true;
            throw PeerClosed(peer + ": the peer closed the connection");
        }
        if (errno != EINTR && errno != EAGAIN && errno != EWOULDBLOCK)
            throw_errno(peer, "recv", errno);
    }
}

bool wait_ready(const Socket& s, bool for_write, double timeout_s, const std::string& peer) {
    return wait_for(s.fd(), for_write ? POLLOUT : POLLIN, deadline_after(timeout_s), peer) != 0;
}

Socket connect_tcp(const std::string& host, int port, double timeout_s) {
    const std::string peer = host_port(host, port);
    const auto deadline = deadline_after(timeout_s);
    if (port < 1 || port > 65535) throw NetError(peer + ": connect: expected a port 1..65535");
    // No AI_ADDRCONFIG: on a host with only loopback up it would hide "localhost" itself.
    const AddrInfo addrs = resolve(host, port, 0, peer);
    int err = 0;
    for (const addrinfo* a = addrs.get(); a != nullptr; a = a->ai_next) {
        Socket s = connect_one(*a, deadline, peer, err);
        if (s.valid()) return s;
        if (err == 0) break;  // out of time
    }
    if (err == 0) {
        std::ostringstream text;
        text << peer << ": connect: no answer within " << timeout_s << " s";
        throw NetError(text.str());
    }
    throw_errno(peer, "connect", err);
}

Listener Listener::open(const std::string& address, int port, int backlog) {
    const std::string where = host_port(address, port);
    if (port < 0 || port > 65535) throw NetError(where + ": listen: expected a port 0..65535");
    const AddrInfo addrs = resolve(address, port, AI_PASSIVE, where);
    const addrinfo& a = *addrs;
    Socket s(::socket(a.ai_family, a.ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, a.ai_protocol));
    if (!s.valid()) throw_errno(where, "socket", errno);
    const int on = 1;
    if (::setsockopt(s.fd(), SOL_SOCKET, SO_REUSEADDR, &on, sizeof on) != 0)
        throw_errno(where, "setsockopt(SO_REUSEADDR)", errno);
    if (::bind(s.fd(), a.ai_addr, a.ai_addrlen) != 0) throw_errno(where, "bind", errno);
    if (::listen(s.fd(), backlog) != 0) throw_errno(where, "listen", errno);
    sockaddr_storage bound{};
    socklen_t len = sizeof bound;
    if (::getsockname(s.fd(), reinterpret_cast<sockaddr*>(&bound), &len) != 0)
        throw_errno(where, "getsockname", errno);
    const int bound_port =
        ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<const sockaddr_in6&>(bound).sin6_port
                                          : reinterpret_cast<const sockaddr_in&>(bound).sin_port);
    return Listener(std::move(s), address, bound_port);
}

std::optional<Socket> Listener::accept(double timeout_s, std::string* peer) {
    const std::string where = host_port(address_, port_);
    if (!socket_.valid()) throw NetError(where + ": accept: the listener is closed");
    const auto deadline = deadline_after(timeout_s);
    for (;;) {
        if (wait_for(socket_.fd(), POLLIN, deadline, where) == 0) return std::nullopt;
        sockaddr_storage addr{};
        socklen_t len = sizeof addr;
        // The listening socket is non-blocking, so a connection that went away between poll and
        // accept4 cannot block this call; the accepted socket is blocking, like connect_tcp's.
        Socket s(::accept4(socket_.fd(), reinterpret_cast<sockaddr*>(&addr), &len, SOCK_CLOEXEC));
        if (s.valid()) {
            set_nodelay(s.fd());
            if (peer) *peer = numeric_peer(reinterpret_cast<const sockaddr*>(&addr), len);
            return s;
        }
        // A connection reset before accept, a signal, or one taken by another thread: wait on.
        if (errno != ECONNABORTED && errno != EINTR && errno != EAGAIN && errno != EWOULDBLOCK &&
            errno != EPROTO)
            throw_errno(where, "accept", errno);
    }
}

}  // namespace isowall::remote
