#include "remote/net/tcp_progress.h"

#include "remote/net/endpoint.h"

#include <arpa/inet.h>

#include <cstddef>
#include <cstring>

// The kernel's tcp_info (glibc's netinet/tcp.h stops before tcpi_bytes_acked, Linux 4.1).
#include <linux/sockios.h>
#include <linux/tcp.h>
#include <netinet/in.h>
#include <sys/ioctl.h>
#include <sys/socket.h>

namespace isowall::remote {
namespace {

bool same_address(const sockaddr_storage& a, const sockaddr_storage& b) {
    if (a.ss_family != b.ss_family) return false;
    if (a.ss_family == AF_INET)
        return reinterpret_cast<const sockaddr_in&>(a).sin_addr.s_addr ==
               reinterpret_cast<const sockaddr_in&>(b).sin_addr.s_addr;
    if (a.ss_family == AF_INET6)
        return std::memcmp(&reinterpret_cast<const sockaddr_in6&>(a).sin6_addr,
                           &reinterpret_cast<const sockaddr_in6&>(b).sin6_addr,
                           sizeof(in6_addr)) == 0;
    return false;
}

bool same_host(int fd) {
    sockaddr_storage peer{}, self{};
    socklen_t peer_size = sizeof peer, self_size = sizeof self;
    if (::getpeername(fd, reinterpret_cast<sockaddr*>(&peer), &peer_size) != 0 ||
        ::getsockname(fd, reinterpret_cast<sockaddr*>(&self), &self_size) != 0)
        return false;
    return is_loopback_address(peer) || same_address(peer, self);
}

}  // namespace

std::optional<TcpProgress> tcp_progress(int fd) {
    if (fd < 0) return std::nullopt;
    tcp_info info{};
    socklen_t size = sizeof info;
    if (::getsockopt(fd, IPPROTO_TCP, TCP_INFO, &info, &size) != 0) return std::nullopt;
    // An older kernel fills less: without tcpi_bytes_acked there is no progress to read.
    constexpr socklen_t kWithAcked = offsetof(tcp_info, tcpi_bytes_acked) + sizeof(__u64);
    int unacked = 0;
    if (size < kWithAcked || ::ioctl(fd, SIOCOUTQ, &unacked) != 0 || unacked < 0)
        return std::nullopt;
    constexpr socklen_t kWithHeld = offsetof(tcp_info, tcpi_rwnd_limited) + sizeof(__u64);
    const double held_s =
        size >= kWithHeld ? 1e-6 * static_cast<double>(info.tcpi_rwnd_limited) : 0;
    return TcpProgress{info.tcpi_bytes_acked, static_cast<std::size_t>(unacked), held_s,
                       same_host(fd)};
}

}  // namespace isowall::remote
