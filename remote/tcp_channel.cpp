#include <array>
#include <chrono>

#include <sys/socket.h>

#include "remote/message_channel.h"

namespace isowall::remote {

// Ends the sending side, then reads what the client still sends for a moment: closing with
// unread bytes would reset the connection, and the reset can discard the error just sent.
void TcpChannel::close_gracefully() {
    ::shutdown(conn_.socket().fd(), SHUT_WR);
    std::array<std::byte, 4096> buf;
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    try {
        for (std::size_t total = 0; total < (std::size_t{1} << 20);) {
            const double left =
                std::chrono::duration<double>(end - std::chrono::steady_clock::now()).count();
            std::size_t got = 0;
            if (left <= 0 || !recv_some(conn_.socket(), buf, left, got, conn_.peer())) break;
            total += got;
        }
    } catch (const std::exception&) {  // EOF or reset: the client is gone, as it should be
    }
    conn_.shutdown();
}

}  // namespace isowall::remote
