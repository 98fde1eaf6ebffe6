#include "remote/view_client.h"

#include "remote/encoding_choice.h"
#include "remote/net/endpoint.h"
#include "remote/net/socket.h"
#include "remote/net/tls.h"

namespace isowall::remote {

ViewClient::ViewClient(Renderer& renderer, const ClientHello& h) : frames_(renderer) {
    Socket s = connect_tcp(h.host, h.port, h.connect_timeout_s);
    conn_ = std::make_unique<Connection>(std::move(s), host_port(h.host, h.port));
    if (h.tls) connect_tls(conn_->socket(), *h.tls, h.host, conn_->peer(), h.connect_timeout_s);
    HelloMsg hello;
    hello.dataset = h.dataset;
    hello.token = h.token;
    hello.encoding = h.adaptive ? kAdaptiveEncoding : static_cast<std::uint8_t>(h.encoding);
    hello.role = h.role;
    hello.session = h.session;
    hello.takes_exact = h.takes_exact && h.role == SessionRole::none;
    conn_->send(hello);
    reports_ = h.adaptive && h.role != SessionRole::follower;
    std::optional<RemoteMessage> m = conn_->receive(h.connect_timeout_s);
    if (!m)
        throw NetError(conn_->peer() + ": no answer to hello within " +
                       std::to_string(h.connect_timeout_s) + " s");
    if (const auto* e = std::get_if<ErrorMsg>(&*m)) throw RemoteError(e->code, e->text);
    const auto* r = std::get_if<ReadyMsg>(&*m);
    if (!r)
        throw WireError(std::string("view protocol: expected ready, got ") +
                        to_string(type_of(*m)) + " message");
    ready_ = *r;
}

double ViewClient::now_s() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

void ViewClient::request(const FrameView& view, LodSchedule lod, bool cached_groups) {
    RequestMsg r;
    r.request_id = next_id_++;
    r.view = view;
    r.lod = lod;
    r.cached_groups = cached_groups;
    frames_.begin(r, now_s());
    conn_->send(r);
    active_ = true;
}

bool ViewClient::receive_one(double timeout_s) {
    std::optional<RemoteMessage> m = conn_->receive(timeout_s);
    if (!m) return false;
    // Its bytes on the wire: a payload that decodes encodes back to exactly its bytes.
    const std::size_t bytes = kHeaderBytes + encode_payload(*m).size();
    if (const auto* s = std::get_if<SessionMsg>(&*m)) {
        session_ = *s;
    } else if (const auto* r = std::get_if<RequestMsg>(&*m)) {
        frames_.begin(*r, now_s());  // a follower: the presenter's next view
        active_ = true;
    } else if (frames_.handle(*m, bytes, now_s())) {
        active_ = false;
    }
    if (reports_)
        if (const std::optional<DecodeRateMsg> report = frames_.decode_report(now_s()))
            conn_->send(*report);
    return true;
}

const ClientFrameResult* ViewClient::next_frame(double timeout_s) {
    bool began = active_;
    for (;;) {
        if (!receive_one(timeout_s)) return nullptr;
        began = began || active_;
        if (began && !active_) return &frames_.result();
    }
}

const ClientFrameResult& ViewClient::wait_done(double timeout_s) {
    while (active_)
        if (!receive_one(timeout_s))
            throw NetError(conn_->peer() + ": nothing received for " + std::to_string(timeout_s) +
                           " s while waiting for the end of frame");
    frames_.measure();
    return frames_.result();
}

bool ViewClient::receive_for(double seconds) {
    // The whole pause, as a script's `wait time` says, whether or not the frame ends first.
    const double end = now_s() + seconds;
    for (double left = seconds; left > 0; left = end - now_s()) receive_one(left);
    return !active_;
}

void ViewClient::close() {
    try {
        conn_->send(ByeMsg{});
    } catch (const NetError&) {
    }
    conn_->shutdown();
}

}  // namespace isowall::remote
