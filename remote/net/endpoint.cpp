#include "remote/net/endpoint.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "core/error.h"

namespace isowall::remote {
namespace {

// A DNS name is at most 253 characters; an address (an IPv6 one with a zone) is shorter.
constexpr std::size_t kMaxHostChars = 253;

bool host_char(char c) {
    return c > ' ' && c < 127 && c != '[' && c != ']' && c != '/' && c != '@';
}

// min_port.."65535" exactly: digits only (no sign, no spaces), no more than five of them; -1 when
// the text is not such a port.
int parse_port(std::string_view text, int min_port) {
    if (text.empty() || text.size() > 5) return -1;
    int port = 0;
    for (const char c : text) {
        if (c < '0' || c > '9') return -1;
        port = port * 10 + (c - '0');
    }
    return port >= min_port && port <= 65535 ? port : -1;
}

[[noreturn]] void fail(std::string_view source, std::string_view field, const std::string& why) {
    throw InputError(std::string(source), std::string(field), why);
}

void check_host(std::string_view host, std::string_view text, std::string_view source,
                std::string_view field) {
    if (host.empty())
        fail(source, field,
             "host: expected a name or an address before the port, got " + quote(text));
    if (host.size() > kMaxHostChars)
        fail(source, field,
             "host: expected at most " + std::to_string(kMaxHostChars) + " characters, got " +
                 std::to_string(host.size()));
    for (const char c : host)
        if (!host_char(c))
            fail(source, field, "host: expected a name or an address, got " + quote(host));
}

// "HOST:PORT" or "[IPV6]:PORT" with a port of min_port..65535.
Endpoint parse_host_port(std::string_view text, int min_port, std::string_view source,
                         std::string_view field) {
    const std::string expected = "expected HOST:PORT or [IPV6]:PORT, got " + quote(text);
    std::string_view host, port;
    if (!text.empty() && text.front() == '[') {
        const std::size_t close = text.find(']');
        if (close == std::string_view::npos)
            fail(source, field, "expected a ']' after the IPv6 address, got " + quote(text));
        host = text.substr(1, close - 1);
        const std::string_view rest = text.substr(close + 1);
        if (rest.empty() || rest.front() != ':') fail(source, field, expected);
        port = rest.substr(1);
    } else {
        const std::size_t colon = text.rfind(':');
        if (colon == std::string_view::npos) fail(source, field, expected);
        host = text.substr(0, colon);
        port = text.substr(colon + 1);
        if (host.find(':') != std::string_view::npos)
            fail(source, field,
                 "an IPv6 address goes in brackets, as [::1]:5000; got " + quote(text));
    }
    check_host(host, text, source, field);
    const int port_number = parse_port(port, min_port);
    if (port_number < 0)
        fail(source, field,
             "port: expected an integer " + std::to_string(min_port) + "..65535, got " +
                 quote(port));
    return {std::string(host), port_number};
}

}  // namespace

Endpoint parse_endpoint(std::string_view text, std::string_view source, std::string_view field) {
    return parse_host_port(text, 1, source, field);
}

Endpoint parse_listen_endpoint(std::string_view text, int default_port, std::string_view source,
                               std::string_view field) {
    // With a port: "[IPV6]:PORT", or "HOST:PORT" with a single colon (a bare IPv6 has several).
    const bool port_given = text.find(']') != std::string_view::npos
                                ? text.back() != ']'
                                : std::count(text.begin(), text.end(), ':') == 1;
    if (port_given) return parse_host_port(text, 0, source, field);  // 0: any free port
    std::string_view host = text;
    if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
        host = host.substr(1, host.size() - 2);
    check_host(host, text, source, field);
    return {std::string(host), default_port};
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

bool is_loopback_address(const sockaddr_storage& a) {
    if (a.ss_family == AF_INET)
        return (ntohl(reinterpret_cast<const sockaddr_in&>(a).sin_addr.s_addr) >> 24) == 127;
    if (a.ss_family != AF_INET6) return false;
    const in6_addr& v6 = reinterpret_cast<const sockaddr_in6&>(a).sin6_addr;
    if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
    // ::ffff:127.x.y.z
    return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
}

bool listens_on_loopback_only(const std::string& host) {
    // The hints of a listener's resolve (socket.cpp: Listener::open).
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
    addrinfo* out = nullptr;
    if (::getaddrinfo(host.c_str(), "0", &hints, &out) != 0) return false;
    bool all = out != nullptr;
    for (const addrinfo* a = out; a; a = a->ai_next) {
        sockaddr_storage s{};
        std::memcpy(&s, a->ai_addr, std::min<std::size_t>(a->ai_addrlen, sizeof s));
        all = all && is_loopback_address(s);
    }
    ::freeaddrinfo(out);
    return all;
}

}  // namespace isowall::remote
