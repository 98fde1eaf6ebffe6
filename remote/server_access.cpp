// Who may reach `isowall serve` (view_server.h): tokens compared in constant time, loopback
// addresses, and what an address off loopback needs (TLS and a token).
#include "remote/view_server.h"

namespace isowall::remote {

bool same_token(const std::string& a, const std::string& b) {
    unsigned diff = a.size() == b.size() ? 0u : 1u;
    for (std::size_t i = 0; i < b.size(); ++i)
        diff |= static_cast<unsigned>(static_cast<unsigned char>(i < a.size() ? a[i] : 0) ^
                                      static_cast<unsigned char>(b[i]));
    return diff == 0;
}

bool is_loopback(const std::string& address) {
    return address == "localhost" || address == "::1" || address.rfind("127.", 0) == 0;
}

std::string exposure_problem(const ServerOptions& o, const std::string& what) {
    if (is_loopback(o.address) || (!o.token.empty() && o.tls)) return "";
    return what + " on " + o.address +
           " (not loopback) needs TLS (--tls-cert and --tls-key) and --token, which every "
           "client must present: anyone on the path could read the surfaces and the token";
}

}  // namespace isowall::remote
