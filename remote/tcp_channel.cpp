#include <sys/socket.h>

#include <array>
#include <chrono>

#include "remote/message_channel.h"
#include "remote/net/tcp_progress.h"
#include "remote/view_framing.h"

namespace isowall::remote {

// A TLS port first looks at what the client sent without taking it: a client that speaks the
// plain protocol gets its error in plain text, which it can read, instead of a failed handshake.
void TcpChannel::open(double timeout_s) {
    if (!tls_) return;
    Socket& s = conn_.socket();
    if (!wait_ready(s, false, timeout_s, conn_.peer()))
        throw TlsHandshakeError(conn_.peer() + ": TLS handshake: nothing came within " +
                                std::to_string(timeout_s) + " s");
    std::array<std::byte, 2> first{};
    const ssize_t n = ::recv(s.fd(), first.data(), first.size(), MSG_PEEK | MSG_DONTWAIT);
    if (n > 0 && !looks_like_tls(std::span(first).first(static_cast<std::size_t>(n))))
        throw WireError(
            "this port speaks TLS (serve --tls-cert) and the client spoke plain text: connect "
            "with isowall view --tls (or --tls-ca FILE)");
    conn_.start_tls(TlsSession::accept(*tls_, s, conn_.peer(), timeout_s));
}

// Ends the sending side, then reads what the client still sends for a moment: closing with
// unread bytes would reset the connection, and the reset can discard the error just sent.
std::optional<LinkProgress> TcpChannel::link_progress() const {
    // Sends write whole messages into the socket before they return: nothing waits on this side.
    const std::optional<TcpProgress> tcp = tcp_progress(conn_.socket().fd());
    if (!tcp) return std::nullopt;
    return LinkProgress{0, tcp->acked, tcp->unacked, tcp->receiver_held_s, tcp->same_host};
}

void TcpChannel::close_gracefully() {
    if (TlsSession* t = conn_.tls()) t->close_notify();
    ::shutdown(conn_.socket().fd(), SHUT_WR);
    std::array<std::byte, 4096> buf;
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    try {
        for (std::size_t total = 0; total < (std::size_t{1} << 20);) {
            const double left =
                std::chrono::duration<double>(end - std::chrono::steady_clock::now()).count();
            std::size_t got = 0;
            if (left <= 0 || !recv_some(conn_.socket(), buf, left, got, conn_.peer())) break;
            total += got;
        }
    } catch (const std::exception&) {  // EOF or reset: the client is gone, as it should be
    }
    conn_.shutdown();
}

}  // namespace isowall::remote
