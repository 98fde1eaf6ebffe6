#include "remote/server_refusal.h"

#include <string_view>

namespace isowall::remote {

ErrorCode code_of(const WireError& e) {
    const std::string_view what = e.what();
    if (what.find("version") != std::string_view::npos) return ErrorCode::unsupported_version;
    if (what.find("over the limit") != std::string_view::npos) return ErrorCode::too_large;
    return ErrorCode::malformed;
}

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
