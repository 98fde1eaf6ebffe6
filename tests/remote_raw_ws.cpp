#include "tests/remote_raw_ws.h"

#include <array>
#include <chrono>
#include <stdexcept>

#include "remote/view_framing.h"

namespace isowall::test {
namespace {

using Clock = std::chrono::steady_clock;

Clock::time_point after(double seconds) {
    return Clock::now() +
           std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

double left_s(Clock::time_point end) {
    return std::max(0.0, std::chrono::duration<double>(end - Clock::now()).count());
}

std::span<const std::byte> as_bytes(const std::string& s) {
    return std::as_bytes(std::span(s.data(), s.size()));
}

}  // namespace

RawWs::RawWs(int port, double timeout_s) : socket_(remote::connect_tcp("127.0.0.1", port, 5)) {
    const std::string head = "GET /ws HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                             "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                             "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                             "Sec-WebSocket-Version: 13\r\n\r\n";
    remote::send_all(socket_, as_bytes(head), "server");
    const auto end = after(timeout_s);
    std::array<std::byte, 4096> buf;
    std::size_t head_end = std::string::npos;
    while ((head_end = buffer_.find("\r\n\r\n")) == std::string::npos) {
        std::size_t got = 0;
        if (!remote::recv_some(socket_, buf, left_s(end), got, "server"))
            throw std::runtime_error("raw ws: no handshake reply within the timeout");
        buffer_.append(reinterpret_cast<const char*>(buf.data()), got);
    }
    if (buffer_.rfind("HTTP/1.1 101", 0) != 0)
        throw std::runtime_error("raw ws: handshake refused: " + buffer_.substr(0, head_end));
    buffer_.erase(0, head_end + 4);
}

std::vector<std::byte> RawWs::frame(std::uint8_t opcode, std::span<const std::byte> payload) {
    const std::array<std::uint8_t, 4> mask = {0x37, 0xfa, 0x21, 0x3d};
    std::vector<std::byte> out;
    out.push_back(std::byte(0x80 | opcode));
    const std::size_t n = payload.size();
    if (n < 126) {
        out.push_back(std::byte(0x80 | n));
    } else if (n < 65536) {
        out.push_back(std::byte(0x80 | 126));
        out.push_back(std::byte(n >> 8));
        out.push_back(std::byte(n & 0xff));
    } else {
        out.push_back(std::byte(0x80 | 127));
        for (int shift = 56; shift >= 0; shift -= 8) out.push_back(std::byte((n >> shift) & 0xff));
    }
    for (std::uint8_t m : mask) out.push_back(std::byte(m));
    for (std::size_t i = 0; i < n; ++i) out.push_back(payload[i] ^ std::byte(mask[i % 4]));
    return out;
}

std::vector<std::byte> RawWs::frame(std::uint8_t opcode, const std::string& payload) {
    return frame(opcode, as_bytes(payload));
}

void RawWs::send_raw(std::span<const std::byte> bytes) {
    remote::send_all(socket_, bytes, "server");
}

void RawWs::send_message(const remote::RemoteMessage& m) {
    send_raw(frame(ws_opcode::kBinary, remote::encode_frame(m)));
}

// One whole server frame from the front of buffer_ (servers do not mask), or nullopt.
std::optional<RawWsFrame> RawWs::parse() {
    if (buffer_.size() < 2) return std::nullopt;
    const auto byte = [this](std::size_t i) { return static_cast<std::uint8_t>(buffer_[i]); };
    std::size_t n = byte(1) & 0x7f, at = 2;
    if (n >= 126) {
        const std::size_t bytes = n == 126 ? 2 : 8;
        if (buffer_.size() < 2 + bytes) return std::nullopt;
        n = 0;
        for (std::size_t i = 0; i < bytes; ++i) n = (n << 8) | byte(2 + i);
        at += bytes;
    }
    if (buffer_.size() < at + n) return std::nullopt;
    RawWsFrame f{static_cast<std::uint8_t>(byte(0) & 0x0f), buffer_.substr(at, n)};
    buffer_.erase(0, at + n);
    return f;
}

std::optional<RawWsFrame> RawWs::receive(double timeout_s) {
    const auto end = after(timeout_s);
    std::array<std::byte, 64 * 1024> buf;
    for (;;) {
        if (std::optional<RawWsFrame> f = parse()) return f;
        std::size_t got = 0;
        if (!remote::recv_some(socket_, buf, left_s(end), got, "server")) return std::nullopt;
        buffer_.append(reinterpret_cast<const char*>(buf.data()), got);
    }
}

remote::RemoteMessage RawWs::receive_message(double timeout_s) {
    const auto end = after(timeout_s);
    for (;;) {
        std::optional<RawWsFrame> f = receive(left_s(end));
        if (!f) throw std::runtime_error("raw ws: no message within the timeout");
        if (f->opcode == ws_opcode::kPong) continue;
        if (f->opcode != ws_opcode::kBinary)
            throw std::runtime_error("raw ws: expected a binary message, got opcode " +
                                     std::to_string(f->opcode));
        return remote::decode_frame(as_bytes(f->payload));
    }
}

bool RawWs::wait_closed(double timeout_s, int* close_code) {
    const auto end = after(timeout_s);
    if (close_code) *close_code = 0;
    try {
        while (std::optional<RawWsFrame> f = receive(left_s(end))) {
            if (f->opcode != ws_opcode::kClose) continue;
            if (close_code && f->payload.size() >= 2)
                *close_code = static_cast<std::uint8_t>(f->payload[0]) << 8 |
                              static_cast<std::uint8_t>(f->payload[1]);
            return true;
        }
    } catch (const remote::PeerClosed&) {
        return true;
    }
    return false;
}

}  // namespace isowall::test
