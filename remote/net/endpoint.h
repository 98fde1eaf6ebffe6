#pragma once
// "HOST:PORT" as a user writes it on the command line (`isowall view 127.0.0.1:5000`).
#include <sys/socket.h>

#include <string>
#include <string_view>

namespace isowall::remote {

struct Endpoint {
    std::string host;  // a name or a numeric address, IPv6 without its brackets
    int port = 0;      // 1..65535
};

// "HOST:PORT", or "[IPV6]:PORT" (an IPv6 address has colons of its own, so it goes in brackets).
// Throws InputError(source, field, ...) saying what was expected and quoting what was found, e.g.
// InputError("--connect", "endpoint", "port: expected an integer 1..65535, got \"0\"").
Endpoint parse_endpoint(std::string_view text, std::string_view source, std::string_view field);

// Where a server listens, in the same form as parse_endpoint's: "HOST:PORT" or "[IPV6]:PORT",
// where PORT may also be 0 (any free port). The port may be left out ("HOST", "[IPV6]", or a bare
// IPv6 address such as "::1"): it is then `default_port`. Throws InputError as parse_endpoint.
Endpoint parse_listen_endpoint(std::string_view text, int default_port, std::string_view source,
                               std::string_view field);

// Whether `address` (a sockaddr_in or sockaddr_in6) is this machine's loopback: 127.0.0.0/8, ::1,
// or ::ffff:127.x.y.z.
bool is_loopback_address(const sockaddr_storage& address);

// Whether listening on `host` reaches this machine only: every address it resolves to, as a
// listener binds it, is loopback. Decided on the addresses, never on the spelling: a name such as
// "127.example" or "localhost.example" may resolve anywhere. False when it resolves to nothing.
bool listens_on_loopback_only(const std::string& host);

// "host:port", with an IPv6 host in brackets: the name of a peer in error lines.
std::string to_string(const Endpoint& e);
std::string host_port(std::string_view host, int port);

}  // namespace isowall::remote
