#include "remote/net/endpoint.h"

#include <algorithm>
#include <string>

#include "common/core/error.h"

namespace isowall::remote {
namespace {

// A DNS name is at most 253 characters; an address (an IPv6 one with a zone) is shorter.
constexpr std::size_t kMaxHostChars = 253;

bool host_char(char c) {
    return c > ' ' && c < 127 && c != '[' && c != ']' && c != '/' && c != '@';
}

// "1".."65535" exactly: digits only (no sign, no spaces), no more than five of them.
int parse_port(std::string_view text) {
    if (text.empty() || text.size() > 5) return 0;
    int port = 0;
    for (const char c : text) {
        if (c < '0' || c > '9') return 0;
        port = port * 10 + (c - '0');
    }
    return port <= 65535 ? port : 0;
}

}  // namespace

Endpoint parse_endpoint(std::string_view text, std::string_view source, std::string_view field) {
    const auto fail = [&](const std::string& why) {
        throw InputError(std::string(source), std::string(field), why);
    };
    const std::string expected = "expected HOST:PORT or [IPV6]:PORT, got " + quote(text);
    std::string_view host, port;
    if (!text.empty() && text.front() == '[') {
        const std::size_t close = text.find(']');
        if (close == std::string_view::npos)
            fail("expected a ']' after the IPv6 address, got " + quote(text));
        host = text.substr(1, close - 1);
        const std::string_view rest = text.substr(close + 1);
        if (rest.empty() || rest.front() != ':') fail(expected);
        port = rest.substr(1);
    } else {
        const std::size_t colon = text.rfind(':');
        if (colon == std::string_view::npos) fail(expected);
        host = text.substr(0, colon);
        port = text.substr(colon + 1);
        if (host.find(':') != std::string_view::npos)
            fail("an IPv6 address goes in brackets, as [::1]:5000; got " + quote(text));
    }
    if (host.empty())
        fail("host: expected a name or an address before the port, got " + quote(text));
    if (host.size() > kMaxHostChars)
        fail("host: expected at most " + std::to_string(kMaxHostChars) + " characters, got " +
             std::to_string(host.size()));
    for (const char c : host)
        if (!host_char(c)) fail("host: expected a name or an address, got " + quote(host));
    const int port_number = parse_port(port);
    if (port_number == 0) fail("port: expected an integer 1..65535, got " + quote(port));
    return {std::string(host), port_number};
}

Endpoint parse_listen_endpoint(std::string_view text, int default_port, std::string_view source,
                               std::string_view field) {
    // With a port: "[IPV6]:PORT", or "HOST:PORT" with a single colon (a bare IPv6 has several).
    const bool port_given = text.find(']') != std::string_view::npos
                                ? text.back() != ']'
                                : std::count(text.begin(), text.end(), ':') == 1;
    if (!port_given) {
        std::string_view host = text;
        if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
            host = host.substr(1, host.size() - 2);
        Endpoint e = parse_endpoint(host_port(host, 1), source, field);  // checks the host alone
        e.port = default_port;
        return e;
    }
    // PORT 0 asks for any free port, which a peer's endpoint never has.
    if (text.size() > 2 && text.substr(text.size() - 2) == ":0") {
        Endpoint e =
            parse_endpoint(std::string(text.substr(0, text.size() - 1)) + "1", source, field);
        e.port = 0;
        return e;
    }
    return parse_endpoint(text, source, field);
}

std::string host_port(std::string_view host, int port) {
    // Appended piece by piece: GCC 12 at -O3 warns falsely (-Wrestrict) on the chained operator+.
    const bool brackets = host.find(':') != std::string_view::npos;
    std::string out;
    out.reserve(host.size() + 8);
    if (brackets) out += '[';
    out.append(host);
    if (brackets) out += ']';
    out += ':';
    out += std::to_string(port);
    return out;
}

std::string to_string(const Endpoint& e) {
    return host_port(e.host, e.port);
}

}  // namespace isowall::remote
