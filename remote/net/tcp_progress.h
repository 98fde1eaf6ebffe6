#pragma once
// How far the peer of a TCP socket has taken what was written to it, from the kernel: the bytes
// it acknowledged in all (TCP_INFO's tcpi_bytes_acked) and those written but not acknowledged
// yet (SIOCOUTQ). Bytes acknowledged are at the peer's host, whatever its program does with
// them; bytes unacknowledged are on the way. The adaptive server reads a link's rate from them
// (remote/encoding_choice.h): a send that returns at once says nothing of the link while the
// socket's buffers take the bytes, which on a slow link can be hundreds of kilobytes.
#include <cstddef>
#include <cstdint>
#include <optional>

namespace isowall::remote {

struct TcpProgress {
    std::uint64_t acked = 0;  // bytes acknowledged by the peer since the connection opened
    std::size_t unacked = 0;  // bytes written and not yet acknowledged
    // Seconds in all that sending was held back by the peer's receive window (tcpi_rwnd_limited):
    // a program that does not read as fast as the link brings bytes. 0 on kernels before 4.10.
    double receiver_held_s = 0;
    // The peer is on this host (a loopback address, or this end's own): there is no network
    // between them, and bytes on their way wait for the host's CPUs, not for a link.
    bool same_host = false;
};

// nullopt when `fd` cannot tell (closed, not TCP). Any thread: it only reads the kernel's state.
std::optional<TcpProgress> tcp_progress(int fd);

}  // namespace isowall::remote
