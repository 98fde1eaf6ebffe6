#include "remote/net/socket.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <thread>

#include "remote/net/endpoint.h"
#include "remote/net/net_stream.h"

namespace isowall::remote {
namespace {

using asio::ip::tcp;

// One read into a stream's read-ahead buffer takes at most this much: a large message arrives in
// several reads, never one allocation sized by the peer.
constexpr std::size_t kReadAheadBytes = 64 * 1024;

// Never destroyed: a socket closed during the process's exit still posts its close here.
struct NetThread {
    asio::io_context io;
    asio::executor_work_guard<asio::io_context::executor_type> work{io.get_executor()};
    NetThread() {
        std::thread([this] { io.run(); }).detach();
    }
};

bool peer_went_away(const asio::error_code& e) {
    return e == asio::error::eof || e == asio::error::connection_reset ||
           e == asio::error::broken_pipe || e == asio::error::operation_aborted ||
           e == asio::error::shut_down || e == asio::ssl::error::stream_truncated;
}

void set_nodelay(tcp::socket& s) {
    asio::error_code ignored;  // only latency if it fails
    s.set_option(tcp::no_delay(true), ignored);
}

tcp::resolver::results_type resolve(const std::string& host, int port, tcp::resolver::flags flags,
                                    const std::string& where) {
    tcp::resolver resolver(net_context());
    asio::error_code e;
    // No address_configured: on a host with only loopback up it would hide "localhost" itself.
    auto results =
        resolver.resolve(host, std::to_string(port), flags | tcp::resolver::numeric_service, e);
    if (e) throw NetError(where + ": resolve: " + e.message());
    return results;
}

std::string numeric_peer(const tcp::socket& s) {
    asio::error_code e;
    const tcp::endpoint p = s.remote_endpoint(e);
    if (e) return "unknown peer";
    return host_port(p.address().to_string(), p.port());
}

}  // namespace

asio::io_context& net_context() {
    static NetThread* const thread = new NetThread;
    return thread->io;
}

std::optional<NetClock::time_point> deadline_after(double timeout_s) {
    if (!(timeout_s >= 0) || std::isinf(timeout_s) || timeout_s > 1e9) return std::nullopt;
    return NetClock::now() +
           std::chrono::duration_cast<NetClock::duration>(std::chrono::duration<double>(timeout_s));
}

void Completion::finish(const asio::error_code& e, std::size_t n) {
    {
        std::lock_guard lock(mutex);
        error = e;
        bytes = n;
        done = true;
    }
    done_cv.notify_all();
}

bool Completion::wait(std::optional<NetClock::time_point> deadline) {
    std::unique_lock lock(mutex);
    if (!deadline) {
        done_cv.wait(lock, [this] { return done; });
        return true;
    }
    return done_cv.wait_until(lock, *deadline, [this] { return done; });
}

[[noreturn]] void throw_net_error(const asio::error_code& e, bool shut, const std::string& peer,
                                  const char* what) {
    if (shut) throw PeerClosed(peer + ": the connection was shut down");
    if (e == asio::error::eof || e == asio::ssl::error::stream_truncated)
        throw PeerClosed(peer + ": the peer closed the connection");
    if (peer_went_away(e)) throw PeerClosed(peer + ": " + what + ": " + e.message());
    const std::string reason = tls_reason(e);
    if (!reason.empty()) throw NetError(peer + ": TLS: " + reason);
    throw NetError(peer + ": " + what + ": " + e.message());
}

Stream::Stream(tcp::socket s)
    : tcp(std::move(s)), fd(tcp.native_handle()), ahead(kReadAheadBytes) {}

void Stream::read_ahead_locked() {
    if (reading || ahead_begin < ahead_end || read_error || shut) return;
    reading = true;
    asio::post(net_context(), [self = shared_from_this()] {
        auto done = [self](const asio::error_code& e, std::size_t n) {
            {
                std::lock_guard lock(self->mutex);
                self->reading = false;
                self->ahead_begin = 0;
                self->ahead_end = n;
                if (e && n == 0) self->read_error = e;
            }
            self->read_cv.notify_all();
        };
        const auto buffer = asio::buffer(self->ahead);
        if (self->tls && !self->tls_closed)
            self->tls->async_read_some(buffer, done);
        else
            self->tcp.async_read_some(buffer, done);
    });
}

bool Stream::wait_ahead(std::unique_lock<std::mutex>& lock,
                        std::optional<NetClock::time_point> deadline, const std::string& peer) {
    for (;;) {
        if (shut) throw_net_error({}, true, peer, "recv");
        if (ahead_begin < ahead_end) return true;
        if (read_error) throw_net_error(read_error, false, peer, "recv");
        read_ahead_locked();
        const auto ready = [this] { return shut || ahead_begin < ahead_end || !reading; };
        if (!deadline) {
            read_cv.wait(lock, ready);
        } else if (!read_cv.wait_until(lock, *deadline, ready)) {
            return false;
        }
    }
}

void Stream::cancel_and_settle() {
    asio::post(net_context(), [self = shared_from_this()] {
        asio::error_code ignored;
        self->tcp.cancel(ignored);
    });
    std::unique_lock lock(mutex);
    read_cv.wait(lock, [this] { return !reading; });
}

Socket::Socket(std::shared_ptr<Stream> stream) : stream_(std::move(stream)) {}

Socket::~Socket() {
    close();
}

Socket& Socket::operator=(Socket&& other) noexcept {
    if (this != &other) {
        close();
        stream_ = std::move(other.stream_);
    }
    return *this;
}

void Socket::close() {
    if (!stream_) return;
    // On the net thread, after anything already posted for this socket; the stream itself lives
    // until the last pending operation has ended.
    asio::post(net_context(), [s = std::move(stream_)] {
        asio::error_code ignored;
        s->tcp.close(ignored);
    });
    stream_.reset();
}

void Socket::shutdown_both() {
    if (!stream_) return;
    {
        std::lock_guard lock(stream_->mutex);
        stream_->shut = true;
    }
    stream_->read_cv.notify_all();
    asio::post(net_context(), [s = stream_] {
        asio::error_code ignored;  // not connected, or shut already: fine
        s->tcp.shutdown(tcp::socket::shutdown_both, ignored);
        s->tcp.cancel(ignored);
    });
}

int Socket::native_handle() const {
    return stream_ ? stream_->fd : -1;
}

std::optional<std::vector<std::byte>> Socket::peek(double timeout_s, const std::string& peer) {
    if (!stream_) throw NetError(peer + ": recv: the socket is closed");
    Stream& s = *stream_;
    std::unique_lock lock(s.mutex);
    if (!s.wait_ahead(lock, deadline_after(timeout_s), peer)) return std::nullopt;
    return std::vector<std::byte>(s.ahead.begin() + static_cast<std::ptrdiff_t>(s.ahead_begin),
                                  s.ahead.begin() + static_cast<std::ptrdiff_t>(s.ahead_end));
}

void Socket::finish(double timeout_s, std::size_t max_bytes) {
    if (!stream_) return;
    Stream& s = *stream_;
    const auto deadline = deadline_after(timeout_s);
    if (s.tls && !s.tls_closed) {
        // A pending read and the shutdown's own read may not share the TLS session.
        s.cancel_and_settle();
        {
            std::lock_guard lock(s.mutex);
            s.read_error.clear();
            s.ahead_begin = s.ahead_end = 0;
        }
        std::shared_ptr<Stream> self = stream_;
        run_on_net([self](auto done) { self->tls->async_shutdown([done](auto e) { done(e, 0); }); },
                   [self] {
                       asio::error_code ignored;
                       self->tcp.cancel(ignored);
                   },
                   deadline);
        std::lock_guard lock(s.mutex);
        s.tls_closed = true;
    }
    asio::post(net_context(), [self = stream_] {
        asio::error_code ignored;
        self->tcp.shutdown(tcp::socket::shutdown_send, ignored);
    });
    std::vector<std::byte> sink(4096);
    try {
        for (std::size_t total = 0; total < max_bytes;) {
            std::size_t got = 0;
            const double left =
                deadline ? std::chrono::duration<double>(*deadline - NetClock::now()).count()
                         : -1.0;
            if ((deadline && left <= 0) || !recv_some(*this, sink, left, got, "peer")) break;
            total += got;
        }
    } catch (const NetError&) {  // EOF or reset: the peer is gone, as it should be
    }
}

void send_all(const Socket& socket, std::span<const std::byte> bytes, const std::string& peer) {
    Stream* s = socket.stream();
    if (!s) throw NetError(peer + ": send: the socket is closed");
    std::lock_guard one_send(s->send_mutex);
    {
        std::lock_guard lock(s->mutex);
        if (s->shut) throw_net_error({}, true, peer, "send");
    }
    std::shared_ptr<Stream> self = socket.shared_stream();
    const asio::const_buffer buffer(bytes.data(), bytes.size());
    const asio::error_code e = run_on_net(
        [self, buffer](auto done) {
            if (self->tls && !self->tls_closed)
                asio::async_write(*self->tls, buffer, done);
            else
                asio::async_write(self->tcp, buffer, done);
        },
        [] {}, std::nullopt);
    if (e) {
        bool shut = false;
        {
            std::lock_guard lock(s->mutex);
            shut = s->shut;
        }
        throw_net_error(e, shut, peer, "send");
    }
}

bool recv_some(const Socket& socket, std::span<std::byte> buf, double timeout_s, std::size_t& got,
               const std::string& peer) {
    got = 0;
    Stream* s = socket.stream();
    if (!s) throw NetError(peer + ": recv: the socket is closed");
    std::unique_lock lock(s->mutex);
    if (!s->wait_ahead(lock, deadline_after(timeout_s), peer)) return false;
    got = std::min(buf.size(), s->ahead_end - s->ahead_begin);
    std::memcpy(buf.data(), s->ahead.data() + s->ahead_begin, got);
    s->ahead_begin += got;
    return true;
}

Socket connect_tcp(const std::string& host, int port, double timeout_s) {
    const std::string peer = host_port(host, port);
    const auto deadline = deadline_after(timeout_s);
    if (port < 1 || port > 65535) throw NetError(peer + ": connect: expected a port 1..65535");
    const auto addresses = resolve(host, port, {}, peer);
    auto socket = std::make_shared<tcp::socket>(net_context());
    bool timed_out = false;
    const asio::error_code e = run_on_net(
        [socket, addresses](auto done) {
            asio::async_connect(
                *socket, addresses,
                [done](const asio::error_code& e, const tcp::endpoint&) { done(e, 0); });
        },
        [socket] {
            asio::error_code ignored;
            socket->close(ignored);
        },
        deadline, &timed_out);
    if (timed_out) {
        std::ostringstream text;
        text << peer << ": connect: no answer within " << timeout_s << " s";
        throw NetError(text.str());
    }
    if (e) throw NetError(peer + ": connect: " + e.message());
    set_nodelay(*socket);
    return Socket(std::make_shared<Stream>(std::move(*socket)));
}

void Acceptor::accept_locked() {
    if (accepting || ready || error) return;
    accepting = true;
    asio::post(net_context(), [self = shared_from_this()] {
        self->acceptor.async_accept([self](const asio::error_code& e, tcp::socket s) {
            {
                std::lock_guard lock(self->mutex);
                self->accepting = false;
                // A connection reset before it was taken: wait for the next one.
                if (!e)
                    self->ready.emplace(std::move(s));
                else if (e != asio::error::connection_aborted && e != asio::error::interrupted &&
                         e != asio::error::try_again)
                    self->error = e;
            }
            self->cv.notify_all();
        });
    });
}

Listener::Listener(std::shared_ptr<Acceptor> a, std::string address, int port)
    : acceptor_(std::move(a)), address_(std::move(address)), port_(port) {}

Listener::~Listener() {
    close();
}

Listener Listener::open(const std::string& address, int port, int backlog) {
    const std::string where = host_port(address, port);
    if (port < 0 || port > 65535) throw NetError(where + ": listen: expected a port 0..65535");
    const auto addresses = resolve(address, port, tcp::resolver::passive, where);
    const tcp::endpoint endpoint = addresses.begin()->endpoint();
    tcp::acceptor a(net_context());
    asio::error_code e;
    if (a.open(endpoint.protocol(), e); e) throw NetError(where + ": socket: " + e.message());
    if (a.set_option(tcp::acceptor::reuse_address(true), e); e)
        throw NetError(where + ": setsockopt(SO_REUSEADDR): " + e.message());
    if (a.bind(endpoint, e); e) throw NetError(where + ": bind: " + e.message());
    if (a.listen(backlog, e); e) throw NetError(where + ": listen: " + e.message());
    const int bound_port = a.local_endpoint(e).port();
    if (e) throw NetError(where + ": getsockname: " + e.message());
    return Listener(std::make_shared<Acceptor>(std::move(a)), address, bound_port);
}

std::optional<Socket> Listener::accept(double timeout_s, std::string* peer) {
    const std::string where = host_port(address_, port_);
    if (!acceptor_) throw NetError(where + ": accept: the listener is closed");
    Acceptor& a = *acceptor_;
    const auto deadline = deadline_after(timeout_s);
    std::unique_lock lock(a.mutex);
    a.accept_locked();
    const auto ready = [&a] { return a.ready || a.error || !a.accepting; };
    for (;;) {
        if (!deadline) {
            a.cv.wait(lock, ready);
        } else if (!a.cv.wait_until(lock, *deadline, ready)) {
            return std::nullopt;
        }
        if (a.error) throw NetError(where + ": accept: " + a.error.message());
        if (a.ready) break;
        a.accept_locked();  // the last one was reset before it was taken
    }
    tcp::socket s = std::move(*a.ready);
    a.ready.reset();
    lock.unlock();
    set_nodelay(s);
    if (peer) *peer = numeric_peer(s);
    return Socket(std::make_shared<Stream>(std::move(s)));
}

void Listener::close() {
    if (!acceptor_) return;
    asio::post(net_context(), [a = std::move(acceptor_)] {
        asio::error_code ignored;
        a->acceptor.close(ignored);
    });
    acceptor_.reset();
}

}  // namespace isowall::remote
