#pragma once
// The seam between a client of `isowall serve` and how its messages travel: a TCP connection
// (TcpChannel, one framed byte stream) or a WebSocket (remote/http/, one frame per binary
// message). ViewServer's per-connection logic (hello, worker, interrupts) sees only this.
//
// Threads, as for Connection: any number of senders, one receiver, shutdown() from anywhere.
#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "remote/encoding_choice.h"
#include "remote/net/connection.h"
#include "remote/net/tls.h"
#include "remote/view_protocol.h"

namespace isowall::remote {

class MessageChannel {
  public:
    virtual ~MessageChannel() = default;

    // Who is at the other end, for log lines ("127.0.0.1:51234", "ws 127.0.0.1:51234").
    virtual const std::string& peer() const = 0;
    // What the channel does before the first message, within `timeout_s` (a TCP channel's TLS
    // handshake); on the connection's own thread. Throws TlsHandshakeError when it fails, and
    // WireError (after which the error goes back in plain text) when a client that speaks
    // plain text came to a TLS port.
    virtual void open(double timeout_s) { (void)timeout_s; }
    // Sends one whole message; returns the bytes it took on the wire, frame header included.
    // Throws NetError or PeerClosed (also after shutdown()).
    virtual std::size_t send(const RemoteMessage& m) = 0;
    // The next whole message within `timeout_s`, or nullopt. Throws WireError when what arrived
    // does not decode, PeerClosed when the peer has gone or after shutdown().
    virtual std::optional<RemoteMessage> receive(double timeout_s) = 0;
    // How far the link has taken what was sent (EncodingChooser::LinkProgress); nullopt where
    // the channel cannot tell. Any thread.
    virtual std::optional<LinkProgress> link_progress() const { return std::nullopt; }
    // The emulated link (token bucket on every send); 0: none.
    virtual void set_rate(double bits_per_second) = 0;
    // Wakes a blocked receive and a blocked or paced send; later calls throw PeerClosed.
    virtual void shutdown() = 0;
    // The end of a connection: lets what was sent (an error) reach the peer, then closes.
    virtual void close_gracefully() = 0;
};

// A TCP connection of the protocol: a framed byte stream (remote/net/connection.h), over TLS
// when the server has a context (`tls`, shared by every connection).
class TcpChannel final : public MessageChannel {
  public:
    TcpChannel(Socket s, std::string peer, std::uint32_t max_payload_bytes,
               std::shared_ptr<const TlsContext> tls = nullptr)
        : conn_(std::move(s), std::move(peer), max_payload_bytes), tls_(std::move(tls)) {}

    const std::string& peer() const override { return conn_.peer(); }
    void open(double timeout_s) override;
    std::size_t send(const RemoteMessage& m) override { return conn_.send(m); }
    std::optional<RemoteMessage> receive(double timeout_s) override {
        return conn_.receive(timeout_s);
    }
    std::optional<LinkProgress> link_progress() const override;
    void set_rate(double bits_per_second) override { conn_.set_rate(bits_per_second); }
    void shutdown() override { conn_.shutdown(); }
    void close_gracefully() override;

  private:
    Connection conn_;
    std::shared_ptr<const TlsContext> tls_;
};

}  // namespace isowall::remote
