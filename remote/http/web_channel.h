#pragma once
// A WebSocket of `isowall serve --http` as a MessageChannel: one protocol frame (view_framing.h)
// per binary message each way, so ViewServer serves it with the same Client code as TCP.
//
// The io thread (web_server.h) puts each arriving message into the connection's WebInbox; the
// channel's reader takes them from there. A text message, or bytes that are not exactly one
// frame, break the channel: receive() throws WireError (the Client answers with an ErrorMsg and
// closes), as a broken TCP stream does. So do messages past kMaxInboxBytes waiting unread: the
// io thread reads whatever the client sends, and a request flood while the reader was held up
// would otherwise queue without bound (over TCP the socket's own buffer holds the client back).
#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>

#include "remote/http/web_server.h"
#include "remote/message_channel.h"
#include "remote/net/token_bucket.h"

namespace isowall::remote {

// Messages waiting unread, counted with kInboxMessageBytes each for their bookkeeping. A client's
// message is under 1 KiB (a request under 200 bytes): a thousand requests the reader has not
// taken yet is a flood, not a user turning a view.
inline constexpr std::size_t kMaxInboxBytes = std::size_t{1} << 20;
inline constexpr std::size_t kInboxMessageBytes = 64;

// What the io thread hands a WebSocket's channel: its messages and its end.
struct WebInbox {
    struct Message {
        std::string bytes;
        bool binary = true;
    };
    std::mutex mutex;
    std::condition_variable changed;
    std::deque<Message> messages;
    std::size_t bytes = 0;    // of `messages`, kInboxMessageBytes each on top
    bool overflowed = false;  // a message found the inbox full: the channel breaks after these
    bool closed = false;

    void push(std::string message, bool binary);
    void close();
};

class WebChannel final : public MessageChannel {
  public:
    WebChannel(std::shared_ptr<web::WebServer> server, web::ConnectionId id, std::string peer,
               std::shared_ptr<WebInbox> inbox, std::uint32_t max_payload_bytes);
    ~WebChannel() override;  // closes the WebSocket

    const std::string& peer() const override { return peer_; }
    // Blocks while the connection has more than a few MiB unsent (web::WebOptions), and for the
    // emulated link's tokens; both waits end at shutdown() or when the peer goes.
    std::size_t send(const RemoteMessage& m) override;
    std::optional<RemoteMessage> receive(double timeout_s) override;
    std::optional<LinkProgress> link_progress() const override;
    void set_rate(double bits_per_second) override;
    void shutdown() override;
    // The closing handshake goes after every message already queued (the error just sent).
    void close_gracefully() override { shutdown(); }

  private:
    RemoteMessage decode(const WebInbox::Message& message);
    void pace(std::size_t bytes);  // send_mutex_ held
    [[noreturn]] void throw_closed() const;

    std::shared_ptr<web::WebServer> server_;  // kept alive while a worker may still send
    web::ConnectionId id_;
    std::string peer_;
    std::shared_ptr<WebInbox> inbox_;
    std::uint32_t max_payload_bytes_;
    std::optional<std::string> broken_;  // the WireError that broke the channel, if one did
    std::mutex send_mutex_;
    TokenBucket bucket_;  // guarded by send_mutex_
    std::atomic<bool> shut_down_{false};
};

}  // namespace isowall::remote
