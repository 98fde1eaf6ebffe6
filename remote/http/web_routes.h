#pragma once
// The HTTP side of `isowall serve --http`, pure: which response each GET gets.
//   /, /index.html      the page (web/dist/index.html; RouteContext::index)
//   /<file>             any other file of web/dist/, with its content type
//   /datasets?token=T   {"datasets":[...],"token_required":...}; 403 {"error":"wrong token"}
//                       when the server has a token and T is missing or another
// Anything else is 404, a method other than GET 405; both with a short text body.
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "remote/http/web_assets.h"
#include "remote/http/web_server.h"

namespace isowall::remote {

struct RouteContext {
    std::vector<std::string> datasets;  // in the order the server loaded them
    std::string token;                  // empty: none asked for
    std::span<const WebAsset> assets;
    std::string_view index = "index.html";  // what "/" serves (wall --http: "wall.html")
};

web::HttpResponse route(const web::HttpRequest& request, const RouteContext& context);

// By the name's extension: "app.js" -> "text/javascript; charset=utf-8"; unknown: octet-stream.
std::string content_type_for(std::string_view name);
// The value of `key` in a query string ("a=1&token=x%20y" -> "x y"), percent-decoded ('+' is a
// space); nullopt when absent or when its escapes are malformed.
std::optional<std::string> query_value(std::string_view query, std::string_view key);
// {"datasets":["phantom","head"],"token_required":false}, names escaped as JSON strings.
std::string datasets_json(const std::vector<std::string>& names, bool token_required);

}  // namespace isowall::remote
