#include "remote/net/tls.h"

#include <openssl/err.h>
#include <openssl/ssl.h>
#include <openssl/x509v3.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "remote/net/net_stream.h"

namespace isowall::remote {
namespace {

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
    return owned;
}

bool is_numeric_address(const std::string& host) {
    asio::error_code e;
    asio::ip::make_address(host, e);
    return !e;
}

// Why a client's handshake failed, in words a user can act on.
std::string client_failure(SSL* ssl, const asio::error_code& e, const std::string& host) {
    const long verify = SSL_get_verify_result(ssl);
    if (verify == X509_V_ERR_HOSTNAME_MISMATCH || verify == X509_V_ERR_IP_ADDRESS_MISMATCH)
        return "the server's certificate does not name " + host;
    if (verify != X509_V_OK)
        return std::string("the server's certificate is not trusted (") +
               X509_verify_cert_error_string(verify) +
               "): name the authority that signed it with --tls-ca FILE";
    const std::string reason = tls_reason(e);
    if (reason.empty() || reason == "wrong version number" || reason == "packet length too long" ||
        reason == "record layer failure")
        return "the server does not answer in TLS" + (reason.empty() ? "" : " (" + reason + ")") +
               ": is it a plain port (serve without --tls-cert)?";
    return reason;
}

// Why a server's handshake failed.
std::string server_failure(const asio::error_code& e) {
    const std::string reason = tls_reason(e);
    if (reason.empty()) return "the client closed the connection";
    if (reason.find("alert") != std::string::npos) return "the client refused it (" + reason + ")";
    return reason;
}

// The handshake on `socket`, as the server (`host` empty: with the bytes peek() showed as its
// first) or as the client of `host`.
void handshake(Socket& socket, const TlsContext& ctx, const std::string& host,
               const std::string& peer, double timeout_s) {
    const bool server = host.empty();
    if (!socket.valid()) throw NetError(peer + ": TLS: the socket is closed");
    std::shared_ptr<Stream> s = socket.shared_stream();
    std::vector<std::byte> first;
    {
        // Nothing is pending on the stream: the server's peek ended its read, the client has
        // not read yet.
        std::lock_guard lock(s->mutex);
        first.assign(s->ahead.begin() + static_cast<std::ptrdiff_t>(s->ahead_begin),
                     s->ahead.begin() + static_cast<std::ptrdiff_t>(s->ahead_end));
        s->ahead_begin = s->ahead_end = 0;
    }
    SSL_CTX_up_ref(ctx.native());  // the asio context below takes this reference
    asio::ssl::context context(ctx.native());
    s->tls = std::make_unique<TlsStream>(s->tcp, context);
    SSL* ssl = s->tls->native_handle();
    if (!server) {
        if (is_numeric_address(host)) {
            X509_VERIFY_PARAM_set1_ip_asc(SSL_get0_param(ssl), host.c_str());
        } else {
            SSL_set1_host(ssl, host.c_str());
            SSL_set_tlsext_host_name(ssl, host.c_str());
        }
    }
    bool timed_out = false;
    const asio::error_code e = run_on_net(
        [s, server, first = std::make_shared<std::vector<std::byte>>(std::move(first))](auto done) {
            if (server)  // `first` lives until the handshake has taken it
                s->tls->async_handshake(
                    asio::ssl::stream_base::server, asio::buffer(*first),
                    [done, first](const asio::error_code& e, std::size_t n) { done(e, n); });
            else
                s->tls->async_handshake(asio::ssl::stream_base::client,
                                        [done](const asio::error_code& e) { done(e, 0); });
        },
        [s] {
            asio::error_code ignored;
            s->tcp.cancel(ignored);
        },
        deadline_after(timeout_s), &timed_out);
    if (timed_out) {
        std::ostringstream text;
        text << peer << ": TLS handshake: no answer within " << timeout_s << " s";
        throw TlsHandshakeError(text.str());
    }
    if (e)
        throw TlsHandshakeError(peer + ": TLS handshake: " +
                                (server ? server_failure(e) : client_failure(ssl, e, host)));
    s->tls_description = std::string(SSL_get_version(ssl)) + " " + SSL_get_cipher_name(ssl);
}

// A certificate's subjectAltName entries a user reads: "DNS:wall.example.org", "IP:10.0.0.5".
std::vector<std::string> subject_alt_names(X509* cert) {
    std::vector<std::string> out;
    auto* names =
        static_cast<GENERAL_NAMES*>(X509_get_ext_d2i(cert, NID_subject_alt_name, nullptr, nullptr));
    if (!names) return out;
    for (int i = 0; i < sk_GENERAL_NAME_num(names); ++i) {
        const GENERAL_NAME* n = sk_GENERAL_NAME_value(names, i);
        if (n->type == GEN_DNS) {
            const auto* data = reinterpret_cast<const char*>(ASN1_STRING_get0_data(n->d.dNSName));
            out.push_back("DNS:" + std::string(data, static_cast<std::size_t>(std::max(
                                                         0, ASN1_STRING_length(n->d.dNSName)))));
        } else if (n->type == GEN_IPADD && ASN1_STRING_length(n->d.iPAddress) == 4) {
            const unsigned char* a = ASN1_STRING_get0_data(n->d.iPAddress);
            out.push_back("IP:" + std::to_string(a[0]) + "." + std::to_string(a[1]) + "." +
                          std::to_string(a[2]) + "." + std::to_string(a[3]));
        }
    }
    GENERAL_NAMES_free(names);
    return out;
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
    std::string list;
    for (const std::string& name : subject_alt_names(cert))
        list += (list.empty() ? "" : " ") + name;
    if (!list.empty()) text += ", names " + list;
    if (BIO* bio = BIO_new(BIO_s_mem())) {
        ASN1_TIME_print(bio, X509_get0_notAfter(cert));
        char* data = nullptr;
        const long n = BIO_get_mem_data(bio, &data);
        text += ", valid until " + std::string(data, static_cast<std::size_t>(std::max(0L, n)));
        BIO_free(bio);
    }
    return text;
}

std::vector<std::string> TlsContext::certificate_dns_names() const {
    std::vector<std::string> out;
    X509* cert = server_ ? SSL_CTX_get0_certificate(ctx_.get()) : nullptr;
    if (!cert) return out;
    for (const std::string& name : subject_alt_names(cert))
        if (name.rfind("DNS:", 0) == 0) out.push_back(name.substr(4));
    return out;
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

void accept_tls(Socket& s, const TlsContext& ctx, const std::string& peer, double timeout_s) {
    handshake(s, ctx, "", peer, timeout_s);
}

void connect_tls(Socket& s, const TlsContext& ctx, const std::string& host, const std::string& peer,
                 double timeout_s) {
    handshake(s, ctx, host.empty() ? "localhost" : host, peer, timeout_s);
}

std::string tls_description(const Socket& s) {
    return s.valid() ? s.stream()->tls_description : "";
}

std::string tls_reason(const asio::error_code& e) {
    if (e.category() != asio::error::get_ssl_category()) return "";
    const char* reason = ERR_reason_error_string(static_cast<unsigned long>(e.value()));
    return reason ? reason : e.message();
}

}  // namespace isowall::remote
