// Who may reach `isowall serve` (view_server.h): tokens compared in constant time, loopback
// addresses, and what an address off loopback needs (TLS and a token).
#include "remote/view_server.h"

#include <unistd.h>

#include <climits>

#include "remote/net/endpoint.h"
#include "remote/net/tls.h"

namespace isowall::remote {

bool same_token(const std::string& a, const std::string& b) {
    unsigned diff = a.size() == b.size() ? 0u : 1u;
    for (std::size_t i = 0; i < b.size(); ++i)
        diff |= static_cast<unsigned>(static_cast<unsigned char>(i < a.size() ? a[i] : 0) ^
                                      static_cast<unsigned char>(b[i]));
    return diff == 0;
}

std::string exposure_problem(const ServerOptions& o, const std::string& what) {
    if ((!o.token.empty() && o.tls) || listens_on_loopback_only(o.address)) return "";
    return what + " on " + o.address +
           " (not loopback) needs TLS (--tls-cert and --tls-key) and --token, which every "
           "client must present: anyone on the path could read the surfaces and the token";
}

std::vector<std::string> served_host_names(const ServerOptions& o) {
    std::vector<std::string> names = o.allowed_hosts;
    names.push_back(o.address);  // an address is allowed anyway; a name is one of ours
    char host[HOST_NAME_MAX + 1] = "";
    if (::gethostname(host, sizeof host) == 0) {
        host[HOST_NAME_MAX] = '\0';
        names.emplace_back(host);
    }
    if (o.tls)
        for (const std::string& n : o.tls->certificate_dns_names()) names.push_back(n);
    return names;
}

}  // namespace isowall::remote
