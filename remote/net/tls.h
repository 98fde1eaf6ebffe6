#pragma once
// TLS for the remote-viewing protocol: a context per side (the server's certificate and key,
// checked through OpenSSL so that a bad file is named; the client's trusted authorities) and the
// handshake that turns a connected Socket into a TLS one (asio::ssl on the net thread). After it
// the Socket's sends and receives go through TLS with the same threads, errors and timeouts.
//
// Bad files are InputErrors naming the file and the option (--tls-cert, --tls-key, --tls-ca);
// a handshake that fails is a TlsHandshakeError naming the peer and, in words, why.
#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "remote/net/socket.h"

struct ssl_ctx_st;

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
    // The server certificate's DNS names (subjectAltName), the names clients may reach it by;
    // empty for a client.
    std::vector<std::string> certificate_dns_names() const;
    ssl_ctx_st* native() const { return ctx_.get(); }

  private:
    TlsContext(std::shared_ptr<ssl_ctx_st> ctx, bool server)
        : ctx_(std::move(ctx)), server_(server) {}
    std::shared_ptr<ssl_ctx_st> ctx_;
    bool server_ = false;
};

// The server's handshake on an accepted socket, within `timeout_s`: from then on every byte of
// `s` goes through TLS. The bytes Socket::peek showed are the handshake's first. Throws
// TlsHandshakeError naming `peer` and, in words, why.
void accept_tls(Socket& s, const TlsContext& ctx, const std::string& peer, double timeout_s);
// The client's: `host` is the name (or numeric address) the certificate must carry, and the name
// sent for SNI.
void connect_tls(Socket& s, const TlsContext& ctx, const std::string& host, const std::string& peer,
                 double timeout_s);
// "TLSv1.3 TLS_AES_256_GCM_SHA384" once a handshake has run on `s`, for log lines; "" before.
std::string tls_description(const Socket& s);

// Whether the first bytes a client sent open a TLS handshake record (content type 22, version
// 3.x): how a TLS port tells a client that speaks plain text, to answer it in plain text.
bool looks_like_tls(std::span<const std::byte> first);

}  // namespace isowall::remote
