#include "remote/net/tls.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <openssl/err.h>
#include <openssl/ssl.h>
#include <openssl/x509v3.h>
#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstring>
#include <fstream>

#include "core/error.h"

namespace isowall::remote {
namespace {

using Clock = std::chrono::steady_clock;

// The reason of OpenSSL's error in words ("wrong version number"), the queue emptied; `fallback`
// when it held none. The first reason queued, unless a later one says more than a generic one
// ("no start line" beneath "PEM lib").
std::string take_reason(const std::string& fallback) {
    std::string best;
    while (const unsigned long e = ERR_get_error()) {
        const char* reason = ERR_reason_error_string(e);
        if (!reason) continue;
        const std::string r = reason;
        if (best.empty() || (r != "PEM lib" && r != "system lib" && best == "PEM lib")) best = r;
    }
    return best.empty() ? fallback : best;
}

// An InputError unless `path` can be opened for reading.
void check_readable(const std::string& path, const std::string& option) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, option, std::string("cannot read it: ") + std::strerror(errno));
}

std::shared_ptr<ssl_ctx_st> new_context(bool server) {
    SSL_CTX* ctx = SSL_CTX_new(server ? TLS_server_method() : TLS_client_method());
    if (!ctx) throw NetError("TLS: cannot make a context: " + take_reason("out of memory"));
    std::shared_ptr<ssl_ctx_st> owned(ctx, SSL_CTX_free);
    SSL_CTX_set_min_proto_version(ctx, TLS1_2_VERSION);
    // Writes may end part way (the socket is non-blocking) and are retried from a buffer that
    // has moved on by the part written.
    SSL_CTX_set_mode(ctx, SSL_MODE_ENABLE_PARTIAL_WRITE | SSL_MODE_ACCEPT_MOVING_WRITE_BUFFER);
    return owned;
}

bool is_numeric_address(const std::string& host) {
    unsigned char buf[sizeof(in6_addr)];
    return ::inet_pton(AF_INET, host.c_str(), buf) == 1 ||
           ::inet_pton(AF_INET6, host.c_str(), buf) == 1;
}

void make_non_blocking(const Socket& s, const std::string& peer) {
    const int flags = ::fcntl(s.fd(), F_GETFL);
    if (flags < 0 || ::fcntl(s.fd(), F_SETFL, flags | O_NONBLOCK) != 0)
        throw NetError(peer + ": fcntl(O_NONBLOCK): " + std::strerror(errno));
}

// OpenSSL writes to the socket with write(), which raises SIGPIPE when the peer has gone (the
// plain path uses send's MSG_NOSIGNAL). Each call that may write blocks SIGPIPE in its thread and
// takes a SIGPIPE it raised, so the peer going away is an error (EPIPE), never the end of the
// process, and no signal handler of the program is touched.
class NoSigpipe {
  public:
    NoSigpipe() {
        sigemptyset(&pipe_);
        sigaddset(&pipe_, SIGPIPE);
        sigset_t pending;
        sigpending(&pending);
        was_pending_ = sigismember(&pending, SIGPIPE) == 1;
        pthread_sigmask(SIG_BLOCK, &pipe_, &old_);
    }
    ~NoSigpipe() {
        if (!was_pending_) {
            sigset_t pending;
            sigpending(&pending);
            if (sigismember(&pending, SIGPIPE) == 1) {
                const timespec zero{0, 0};
                sigtimedwait(&pipe_, nullptr, &zero);
            }
        }
        pthread_sigmask(SIG_SETMASK, &old_, nullptr);
    }
    NoSigpipe(const NoSigpipe&) = delete;
    NoSigpipe& operator=(const NoSigpipe&) = delete;

  private:
    sigset_t pipe_, old_;
    bool was_pending_ = false;
};

// Whether OpenSSL's error is the connection ending without TLS's close_notify (OpenSSL 3 calls
// an EOF that: a peer that went away, or this side's shutdown_both()).
bool peer_gone() {
    return ERR_GET_REASON(ERR_peek_error()) == SSL_R_UNEXPECTED_EOF_WHILE_READING;
}

double seconds_left(Clock::time_point deadline) {
    return std::max(0.0, std::chrono::duration<double>(deadline - Clock::now()).count());
}

// Why a client's handshake failed, in words a user can act on.
std::string client_failure(ssl_st* ssl, int ssl_error, const std::string& host) {
    const long verify = SSL_get_verify_result(ssl);
    if (verify == X509_V_ERR_HOSTNAME_MISMATCH || verify == X509_V_ERR_IP_ADDRESS_MISMATCH) {
        ERR_clear_error();
        return "the server's certificate does not name " + host;
    }
    if (verify != X509_V_OK) {
        ERR_clear_error();
        return std::string("the server's certificate is not trusted (") +
               X509_verify_cert_error_string(verify) +
               "): name the authority that signed it with --tls-ca FILE";
    }
    const std::string reason = take_reason("");
    if (ssl_error == SSL_ERROR_SYSCALL || ssl_error == SSL_ERROR_ZERO_RETURN || reason.empty() ||
        reason == "wrong version number" || reason == "packet length too long" ||
        reason == "record layer failure")
        return "the server does not answer in TLS" + (reason.empty() ? "" : " (" + reason + ")") +
               ": is it a plain port (serve without --tls-cert)?";
    return reason;
}

}  // namespace

bool looks_like_tls(std::span<const std::byte> first) {
    if (first.empty()) return false;
    if (first[0] != std::byte{22}) return false;  // a handshake record
    return first.size() < 2 || first[1] == std::byte{3};
}

TlsContext TlsContext::server(const std::string& cert_file, const std::string& key_file) {
    check_readable(cert_file, "--tls-cert");
    check_readable(key_file, "--tls-key");
    std::shared_ptr<ssl_ctx_st> ctx = new_context(true);
    if (SSL_CTX_use_certificate_chain_file(ctx.get(), cert_file.c_str()) != 1)
        throw InputError(cert_file, "--tls-cert",
                         "not a PEM certificate (" + take_reason("unreadable") + ")");
    const std::string mismatch = "this key does not match the certificate in " + cert_file;
    if (SSL_CTX_use_PrivateKey_file(ctx.get(), key_file.c_str(), SSL_FILETYPE_PEM) != 1) {
        const std::string reason = take_reason("unreadable");
        throw InputError(key_file, "--tls-key",
                         reason == "key values mismatch"
                             ? mismatch
                             : "not a PEM private key without a passphrase (" + reason + ")");
    }
    if (SSL_CTX_check_private_key(ctx.get()) != 1) {
        ERR_clear_error();
        throw InputError(key_file, "--tls-key", mismatch);
    }
    if (X509* cert = SSL_CTX_get0_certificate(ctx.get())) {
        if (X509_cmp_current_time(X509_get0_notAfter(cert)) < 0)
            throw InputError(cert_file, "--tls-cert",
                             "the certificate has expired: clients will refuse it");
        if (X509_cmp_current_time(X509_get0_notBefore(cert)) > 0)
            throw InputError(cert_file, "--tls-cert",
                             "the certificate is not valid yet: clients will refuse it");
    }
    return TlsContext(std::move(ctx), true);
}

std::string TlsContext::certificate_summary() const {
    X509* cert = server_ ? SSL_CTX_get0_certificate(ctx_.get()) : nullptr;
    if (!cert) return "";
    std::string text = "subject ";
    char subject[256] = "";
    X509_NAME_oneline(X509_get_subject_name(cert), subject, sizeof subject);
    text += subject;
    if (auto* names = static_cast<GENERAL_NAMES*>(
            X509_get_ext_d2i(cert, NID_subject_alt_name, nullptr, nullptr))) {
        std::string list;
        for (int i = 0; i < sk_GENERAL_NAME_num(names); ++i) {
            const GENERAL_NAME* n = sk_GENERAL_NAME_value(names, i);
            if (n->type == GEN_DNS) {
                list += (list.empty() ? "" : " ") + std::string("DNS:") +
                        reinterpret_cast<const char*>(ASN1_STRING_get0_data(n->d.dNSName));
            } else if (n->type == GEN_IPADD && ASN1_STRING_length(n->d.iPAddress) == 4) {
                const unsigned char* a = ASN1_STRING_get0_data(n->d.iPAddress);
                list += (list.empty() ? "" : " ") + std::string("IP:") + std::to_string(a[0]) +
                        "." + std::to_string(a[1]) + "." + std::to_string(a[2]) + "." +
                        std::to_string(a[3]);
            }
        }
        GENERAL_NAMES_free(names);
        if (!list.empty()) text += ", names " + list;
    }
    if (BIO* bio = BIO_new(BIO_s_mem())) {
        ASN1_TIME_print(bio, X509_get0_notAfter(cert));
        char* data = nullptr;
        const long n = BIO_get_mem_data(bio, &data);
        text += ", valid until " + std::string(data, static_cast<std::size_t>(std::max(0L, n)));
        BIO_free(bio);
    }
    return text;
}

TlsContext TlsContext::client(const std::string& ca_file) {
    std::shared_ptr<ssl_ctx_st> ctx = new_context(false);
    if (ca_file.empty()) {
        if (SSL_CTX_set_default_verify_paths(ctx.get()) != 1)
            throw NetError("TLS: cannot load the system's certificate authorities: " +
                           take_reason("unknown"));
    } else {
        check_readable(ca_file, "--tls-ca");
        if (SSL_CTX_load_verify_locations(ctx.get(), ca_file.c_str(), nullptr) != 1)
            throw InputError(ca_file, "--tls-ca",
                             "no PEM certificate in it (" + take_reason("unreadable") + ")");
    }
    SSL_CTX_set_verify(ctx.get(), SSL_VERIFY_PEER, nullptr);
    return TlsContext(std::move(ctx), false);
}

TlsSession::~TlsSession() {
    SSL_free(ssl_);
}

std::unique_ptr<TlsSession> TlsSession::start(const TlsContext& ctx, const Socket& s,
                                              const std::string& peer) {
    SSL* ssl = SSL_new(ctx.native());
    if (!ssl) throw NetError(peer + ": TLS: " + take_reason("out of memory"));
    std::unique_ptr<TlsSession> session(new TlsSession(ssl));
    if (SSL_set_fd(ssl, s.fd()) != 1) throw NetError(peer + ": TLS: " + take_reason("set_fd"));
    return session;
}

std::unique_ptr<TlsSession> TlsSession::accept(const TlsContext& ctx, const Socket& s,
                                               const std::string& peer, double timeout_s) {
    return handshake(start(ctx, s, peer), s, "", peer, timeout_s);
}

std::unique_ptr<TlsSession> TlsSession::connect(const TlsContext& ctx, const Socket& s,
                                                const std::string& host, const std::string& peer,
                                                double timeout_s) {
    std::unique_ptr<TlsSession> session = start(ctx, s, peer);
    SSL* ssl = session->ssl_;
    if (is_numeric_address(host)) {
        X509_VERIFY_PARAM_set1_ip_asc(SSL_get0_param(ssl), host.c_str());
    } else {
        SSL_set1_host(ssl, host.c_str());
        SSL_set_tlsext_host_name(ssl, host.c_str());
    }
    return handshake(std::move(session), s, host, peer, timeout_s);
}

std::unique_ptr<TlsSession> TlsSession::handshake(std::unique_ptr<TlsSession> session,
                                                  const Socket& s, const std::string& host,
                                                  const std::string& peer, double timeout_s) {
    const bool server = host.empty();
    make_non_blocking(s, peer);
    const auto deadline =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>(std::min(timeout_s, 1e6)));
    SSL* ssl = session->ssl_;
    for (;;) {
        ERR_clear_error();
        errno = 0;
        int rc = 0, err = 0;
        {
            const NoSigpipe no_sigpipe;
            rc = server ? SSL_accept(ssl) : SSL_connect(ssl);
            if (rc == 1) return session;
            err = SSL_get_error(ssl, rc);
        }
        if (err == SSL_ERROR_WANT_READ || err == SSL_ERROR_WANT_WRITE) {
            if (!wait_ready(s, err == SSL_ERROR_WANT_WRITE, seconds_left(deadline), peer))
                throw TlsHandshakeError(peer + ": TLS handshake: no answer within " +
                                        std::to_string(timeout_s) + " s");
            continue;
        }
        if (!server)
            throw TlsHandshakeError(peer + ": TLS handshake: " + client_failure(ssl, err, host));
        const std::string reason = take_reason("");
        const bool alert = reason.find("alert") != std::string::npos;
        throw TlsHandshakeError(peer + ": TLS handshake: " +
                                (reason.empty() ? std::string("the client closed the connection")
                                 : alert        ? "the client refused it (" + reason + ")"
                                                : reason));
    }
}

void TlsSession::write_all(const Socket& s, std::span<const std::byte> bytes,
                           const std::string& peer) {
    while (!bytes.empty()) {
        int err = 0;
        {
            std::lock_guard lock(mutex_);
            const NoSigpipe no_sigpipe;
            ERR_clear_error();
            errno = 0;
            const int n = SSL_write(ssl_, bytes.data(),
                                    static_cast<int>(std::min<std::size_t>(bytes.size(), INT_MAX)));
            if (n > 0) {
                bytes = bytes.subspan(static_cast<std::size_t>(n));
                continue;
            }
            err = SSL_get_error(ssl_, n);
        }
        if (err == SSL_ERROR_WANT_WRITE) {
            wait_ready(s, true, -1, peer);  // a shutdown_both() wakes it
        } else if (err == SSL_ERROR_WANT_READ) {
            // Short waits: the reader may take the bytes this write waits for.
            wait_ready(s, false, 0.05, peer);
        } else if (err == SSL_ERROR_SYSCALL && errno != 0 && errno != EPIPE &&
                   errno != ECONNRESET) {
            throw NetError(peer + ": send: " + std::strerror(errno));
        } else if (err == SSL_ERROR_SSL && !peer_gone()) {
            throw NetError(peer + ": TLS: " + take_reason("write failed"));
        } else {
            ERR_clear_error();
            throw PeerClosed(peer + ": the peer closed the connection");
        }
    }
}

bool TlsSession::read_some(const Socket& s, std::span<std::byte> buf, double timeout_s,
                           std::size_t& got, const std::string& peer) {
    got = 0;
    const bool forever = !(timeout_s >= 0) || std::isinf(timeout_s) || timeout_s > 1e9;
    const auto deadline = forever ? Clock::time_point::max()
                                  : Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                       std::chrono::duration<double>(timeout_s));
    for (;;) {
        int err = 0;
        {
            std::lock_guard lock(mutex_);
            const NoSigpipe no_sigpipe;  // a read may write (TLS 1.3's key updates, alerts)
            ERR_clear_error();
            errno = 0;
            const int n = SSL_read(ssl_, buf.data(),
                                   static_cast<int>(std::min<std::size_t>(buf.size(), INT_MAX)));
            if (n > 0) {
                got = static_cast<std::size_t>(n);
                return true;
            }
            err = SSL_get_error(ssl_, n);
        }
        if (err == SSL_ERROR_WANT_READ || err == SSL_ERROR_WANT_WRITE) {
            const double left = forever ? 1.0 : seconds_left(deadline);
            if (left <= 0) return false;
            // At most a second per wait: a writer may have taken what this read waits for. The
            // next turn reads again, and ends when the time has run out.
            wait_ready(s, err == SSL_ERROR_WANT_WRITE, std::min(left, 1.0), peer);
            continue;
        }
        if (err == SSL_ERROR_SYSCALL && errno != 0 && errno != EPIPE && errno != ECONNRESET)
            throw NetError(peer + ": recv: " + std::strerror(errno));
        if (err == SSL_ERROR_SSL && !peer_gone())
            throw NetError(peer + ": TLS: " + take_reason("read failed"));
        ERR_clear_error();
        throw PeerClosed(peer + ": the peer closed the connection");
    }
}

void TlsSession::close_notify() {
    std::lock_guard lock(mutex_);
    const NoSigpipe no_sigpipe;
    ERR_clear_error();
    SSL_shutdown(ssl_);  // may not go out on a full socket: the peer then sees an EOF
    ERR_clear_error();
}

std::string TlsSession::describe() const {
    return std::string(SSL_get_version(ssl_)) + " " + SSL_get_cipher_name(ssl_);
}

}  // namespace isowall::remote
