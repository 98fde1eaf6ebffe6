#include "tests/ws_test_client.h"

#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

namespace isowall::test {
namespace {

using Client = websocketpp::client<websocketpp::config::asio_client>;

std::chrono::duration<double> seconds(double s) {
    return std::chrono::duration<double>(s);
}

}  // namespace

struct WsTestClient::Impl {
    Client client;
    websocketpp::connection_hdl handle;
    std::thread thread;
    std::mutex mutex;
    std::condition_variable changed;
    std::deque<WsMessage> messages;
    bool open = false, ended = false;
    std::string failure;

    void end(const std::string& why) {
        {
            std::lock_guard lock(mutex);
            ended = true;
            if (!open && failure.empty()) failure = why;
        }
        changed.notify_all();
    }
};

WsTestClient::WsTestClient(int port, double timeout_s, const std::string& origin)
    : impl_(std::make_unique<Impl>()) {
    Impl& im = *impl_;
    im.client.clear_access_channels(websocketpp::log::alevel::all);
    im.client.clear_error_channels(websocketpp::log::elevel::all);
    im.client.init_asio();
    im.client.set_max_message_size(std::size_t{128} << 20);
    im.client.set_open_handler([&im](websocketpp::connection_hdl) {
        {
            std::lock_guard lock(im.mutex);
            im.open = true;
        }
        im.changed.notify_all();
    });
    im.client.set_fail_handler([&im](websocketpp::connection_hdl h) {
        const auto con = im.client.get_con_from_hdl(h);
        im.end("handshake failed: HTTP " + std::to_string(con->get_response_code()));
    });
    im.client.set_close_handler([&im](websocketpp::connection_hdl) { im.end("closed"); });
    im.client.set_message_handler([&im](websocketpp::connection_hdl, Client::message_ptr m) {
        {
            std::lock_guard lock(im.mutex);
            im.messages.push_back(
                {m->get_payload(), m->get_opcode() == websocketpp::frame::opcode::binary});
        }
        im.changed.notify_all();
    });
    websocketpp::lib::error_code ec;
    const auto con = im.client.get_connection("ws://127.0.0.1:" + std::to_string(port) + "/ws", ec);
    if (ec) throw std::runtime_error("ws client: " + ec.message());
    if (!origin.empty()) con->append_header("Origin", origin);
    im.handle = con->get_handle();
    im.client.connect(con);
    im.thread = std::thread([&im] { im.client.run(); });
    std::unique_lock lock(im.mutex);
    if (!im.changed.wait_for(lock, seconds(timeout_s), [&im] { return im.open || im.ended; }))
        im.failure = "no handshake within " + std::to_string(timeout_s) + " s";
    if (!im.open) {
        const std::string why = im.failure;
        lock.unlock();
        im.client.stop();
        im.thread.join();
        throw std::runtime_error("ws client: " + why);
    }
}

WsTestClient::~WsTestClient() {
    websocketpp::lib::error_code ec;
    impl_->client.close(impl_->handle, websocketpp::close::status::normal, "done", ec);
    wait_closed(2);
    impl_->client.stop();
    impl_->thread.join();
}

void WsTestClient::send_binary(const void* bytes, std::size_t size) {
    websocketpp::lib::error_code ec;
    impl_->client.send(impl_->handle, bytes, size, websocketpp::frame::opcode::binary, ec);
    if (ec) throw std::runtime_error("ws client: send: " + ec.message());
}

void WsTestClient::send_text(const std::string& text) {
    websocketpp::lib::error_code ec;
    impl_->client.send(impl_->handle, text, websocketpp::frame::opcode::text, ec);
    if (ec) throw std::runtime_error("ws client: send: " + ec.message());
}

std::optional<WsMessage> WsTestClient::receive(double timeout_s) {
    Impl& im = *impl_;
    std::unique_lock lock(im.mutex);
    im.changed.wait_for(lock, seconds(timeout_s),
                        [&im] { return !im.messages.empty() || im.ended; });
    if (im.messages.empty()) return std::nullopt;
    WsMessage m = std::move(im.messages.front());
    im.messages.pop_front();
    return m;
}

bool WsTestClient::wait_closed(double timeout_s) {
    Impl& im = *impl_;
    std::unique_lock lock(im.mutex);
    return im.changed.wait_for(lock, seconds(timeout_s), [&im] { return im.ended; });
}

}  // namespace isowall::test
