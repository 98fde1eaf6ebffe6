#pragma once
// TLS for the remote-viewing protocol, through OpenSSL: a context per side (the
// server's certificate and key; the client's trusted authorities) and one connection's session
// over a connected Socket.
//
// A session works on a non-blocking socket: every OpenSSL call holds the session's mutex and
// never blocks, and a call that must wait for the network releases the mutex and polls. So one
// reader and one writer (Connection's threads) may use a session at once, and Socket::
// shutdown_both() from a third thread wakes both (they then throw PeerClosed).
//
// Bad files are InputErrors naming the file and the option (--tls-cert, --tls-key, --tls-ca);
// a handshake that fails is a TlsHandshakeError naming the peer and, in words, why.
#include <cstddef>
#include <memory>
#include <mutex>
#include <span>
#include <string>

#include "remote/net/socket.h"

struct ssl_ctx_st;
struct ssl_st;

namespace isowall::remote {

struct TlsHandshakeError : NetError {
    using NetError::NetError;
};

class TlsContext {
  public:
    // The server's side: a PEM certificate chain and its PEM private key. Checks that both read,
    // that the key matches the certificate and that the certificate has not expired.
    static TlsContext server(const std::string& cert_file, const std::string& key_file);
    // The client's side: the server's certificate must chain to an authority in `ca_file` (PEM;
    // a self-signed server certificate may be its own authority) or, when it is empty, in the
    // system's store, and must name the host the client connects to.
    static TlsContext client(const std::string& ca_file);

    bool is_server() const { return server_; }
    // A server's certificate in one line for its start-up log: "subject CN=wall.example.org,
    // names DNS:wall.example.org, valid until Nov 28 09:41:02 2027 GMT" ("" for a client).
    std::string certificate_summary() const;
    ssl_ctx_st* native() const { return ctx_.get(); }

  private:
    TlsContext(std::shared_ptr<ssl_ctx_st> ctx, bool server)
        : ctx_(std::move(ctx)), server_(server) {}
    std::shared_ptr<ssl_ctx_st> ctx_;
    bool server_ = false;
};

class TlsSession {
  public:
    ~TlsSession();
    TlsSession(const TlsSession&) = delete;
    TlsSession& operator=(const TlsSession&) = delete;

    // The server's handshake on an accepted socket (made non-blocking), within `timeout_s`.
    static std::unique_ptr<TlsSession> accept(const TlsContext& ctx, const Socket& s,
                                              const std::string& peer, double timeout_s);
    // The client's handshake: `host` is the name (or numeric address) the certificate must
    // carry, and the name sent for SNI.
    static std::unique_ptr<TlsSession> connect(const TlsContext& ctx, const Socket& s,
                                               const std::string& host, const std::string& peer,
                                               double timeout_s);

    // As send_all and recv_some (socket.h), through TLS: the same errors, the same timeouts.
    void write_all(const Socket& s, std::span<const std::byte> bytes, const std::string& peer);
    bool read_some(const Socket& s, std::span<std::byte> buf, double timeout_s, std::size_t& got,
                   const std::string& peer);
    // Sends the close_notify alert if the socket takes it at once; never waits.
    void close_notify();
    // "TLSv1.3 TLS_AES_256_GCM_SHA384": for log lines.
    std::string describe() const;

  private:
    explicit TlsSession(ssl_st* ssl) : ssl_(ssl) {}
    // A session of `ctx` on `s`, before its handshake.
    static std::unique_ptr<TlsSession> start(const TlsContext& ctx, const Socket& s,
                                             const std::string& peer);
    // The server's handshake when `host` is empty, else the client's.
    static std::unique_ptr<TlsSession> handshake(std::unique_ptr<TlsSession> session,
                                                 const Socket& s, const std::string& host,
                                                 const std::string& peer, double timeout_s);

    ssl_st* ssl_ = nullptr;
    std::mutex mutex_;
};

// Whether the first bytes a client sent open a TLS handshake record (content type 22, version
// 3.x): how a TLS port tells a client that speaks plain text, to answer it in plain text.
bool looks_like_tls(std::span<const std::byte> first);

}  // namespace isowall::remote
