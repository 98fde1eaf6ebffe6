#include "remote/server_refusal.h"

namespace isowall::remote {

ViewServer::Refusal::Refusal(std::unique_ptr<MessageChannel> c, std::string text)
    : channel(std::move(c)) {
    thread = std::thread([this, text = std::move(text)] {
        within(*channel, kRefusalTimeoutS, [&] {
            try {
                channel->open(kRefusalTimeoutS);
                channel->send(make_error(ErrorCode::internal, text));
            } catch (const std::exception&) {  // gone, or speaks nonsense: nothing to tell
            }
        });
        channel->close_gracefully();
        done = true;
    });
}

ViewServer::Refusal::~Refusal() {
    channel->shutdown();
    thread.join();
}

}  // namespace isowall::remote
