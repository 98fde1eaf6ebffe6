#include "remote/server_refusal.h"

#include <string_view>

namespace isowall::remote {

ErrorCode code_of(const WireError& e) {
    const std::string_view what = e.what();
    if (what.find("version") != std::string_view::npos) return ErrorCode::unsupported_version;
    if (what.find("over the limit") != std::string_view::npos) return ErrorCode::too_large;
    return ErrorCode::malformed;
}

}  // namespace isowall::remote
