#pragma once
// The page's files (web/dist/), embedded into the program at build time by embed_assets.cmake,
// so `isowall serve --http` needs nothing from the source tree at run time.
#include <span>
#include <string_view>

namespace isowall::remote {

struct WebAsset {
    std::string_view name;  // relative to web/dist/, '/'-separated: "index.html", "app.js"
    std::span<const unsigned char> bytes;
};

// Every file of web/dist/ when the program was built, sorted by name (generated web_assets.cpp).
std::span<const WebAsset> web_assets();

}  // namespace isowall::remote
