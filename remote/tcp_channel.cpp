#include <algorithm>
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
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(timeout_s));
    const std::optional<std::vector<std::byte>> first = s.peek(timeout_s, conn_.peer());
    if (!first)
        throw TlsHandshakeError(conn_.peer() + ": TLS handshake: nothing came within " +
                                std::to_string(timeout_s) + " s");
    if (!looks_like_tls(*first))
        throw WireError(
            "this port speaks TLS (serve --tls-cert) and the client spoke plain text: connect "
            "with isowall view --tls (or --tls-ca FILE)");
    const double left =
        std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
    accept_tls(s, *tls_, conn_.peer(), std::max(left, 0.0));
}

std::optional<LinkProgress> TcpChannel::link_progress() const {
    // Sends write whole messages into the socket before they return: nothing waits on this side.
    const std::optional<TcpProgress> tcp = tcp_progress(conn_.socket().native_handle());
    if (!tcp) return std::nullopt;
    return LinkProgress{0, tcp->acked, tcp->unacked, tcp->receiver_held_s, tcp->same_host};
}

// Lets what was sent (an error) reach the client before the connection closes.
void TcpChannel::close_gracefully() {
    conn_.socket().finish(1.0, std::size_t{1} << 20);
    conn_.shutdown();
}

}  // namespace isowall::remote
