#include "files/oiio_module.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace isowall::oiio {
namespace {

constexpr const char* kFileName = "isowall_oiio.so";

// Where to look, in order: $ISOWALL_OIIO_MODULE, beside the running program, where the build
// put it (tests and fuzzers run from folders of their own).
std::vector<std::filesystem::path> candidates() {
    std::vector<std::filesystem::path> out;
    if (const char* env = std::getenv("ISOWALL_OIIO_MODULE"); env && *env) return {env};
    std::error_code ec;
    const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) out.push_back(self.parent_path() / kFileName);
#ifdef ISOWALL_OIIO_MODULE_DIR
    out.push_back(std::filesystem::path(ISOWALL_OIIO_MODULE_DIR) / kFileName);
#endif
    return out;
}

const Api* load(std::string& why) {
    for (const auto& path : candidates()) {
        std::error_code ec;
        if (!std::filesystem::exists(path, ec)) {
            why += (why.empty() ? "" : "; ") + path.string() + ": not found";
            continue;
        }
        void* handle = dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
        if (!handle) {
            why += (why.empty() ? "" : "; ") + std::string(dlerror());
            continue;
        }
        using Entry = const Api* (*)();
        auto entry = reinterpret_cast<Entry>(dlsym(handle, "isowall_oiio_api"));
        const Api* api = entry ? entry() : nullptr;
        if (api && api->version == kApiVersion) return api;  // kept loaded for the process
        why += (why.empty() ? "" : "; ") + path.string() +
               (api ? ": another version of the module" : ": no isowall_oiio_api in it");
        dlclose(handle);
    }
    return nullptr;
}

}  // namespace

const Api& api() {
    static std::once_flag once;
    static const Api* loaded = nullptr;
    static std::string why;
    std::call_once(once, [] { loaded = load(why); });
    if (!loaded)
        throw std::runtime_error("OpenImageIO module " + std::string(kFileName) +
                                 " cannot be loaded: " + why);
    return *loaded;
}

}  // namespace isowall::oiio
