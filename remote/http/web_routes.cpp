#include "remote/http/web_routes.h"

#include <array>
#include <cstdio>
#include <utility>

#include "core/number.h"
#include "remote/view_server.h"

namespace isowall::remote {
namespace {

constexpr std::string_view kText = "text/plain; charset=utf-8";
constexpr std::string_view kJson = "application/json";

web::HttpResponse text(int status, std::string body) {
    return {status, std::string(kText), std::move(body) + "\n"};
}

std::optional<std::string> percent_decode(std::string_view s) {
    std::string out;
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (s[i] == '+') {
            out += ' ';
        } else if (s[i] != '%') {
            out += s[i];
        } else {
            if (i + 2 >= s.size()) return std::nullopt;
            const int hi = hex_digit(s[i + 1]), lo = hex_digit(s[i + 2]);
            if (hi < 0 || lo < 0) return std::nullopt;
            out += static_cast<char>(hi * 16 + lo);
            i += 2;
        }
    }
    return out;
}

void append_json_string(std::string& out, std::string_view s) {
    out += '"';
    for (const char c : s) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            std::array<char, 8> buf{};
            std::snprintf(buf.data(), buf.size(), "\\u%04x", static_cast<unsigned>(c));
            out += buf.data();
        } else {
            out += c;
        }
    }
    out += '"';
}

web::HttpResponse datasets(const web::HttpRequest& request, const RouteContext& context) {
    if (!context.token.empty()) {
        const std::optional<std::string> token = query_value(request.query, "token");
        if (!token || !same_token(*token, context.token))
            return {403, std::string(kJson), "{\"error\":\"wrong token\"}"};
    }
    return {200, std::string(kJson), datasets_json(context.datasets, !context.token.empty())};
}

const WebAsset* find_asset(std::span<const WebAsset> assets, std::string_view name) {
    for (const WebAsset& a : assets)
        if (a.name == name) return &a;
    return nullptr;
}

}  // namespace

std::string content_type_for(std::string_view name) {
    static constexpr std::array<std::pair<std::string_view, std::string_view>, 7> kTypes = {{
        {".html", "text/html; charset=utf-8"},
        {".js", "text/javascript; charset=utf-8"},
        {".css", "text/css; charset=utf-8"},
        {".png", "image/png"},
        {".svg", "image/svg+xml"},
        {".json", "application/json"},
        {".map", "application/json"},
    }};
    for (const auto& [extension, type] : kTypes)
        if (name.size() > extension.size() && name.ends_with(extension)) return std::string(type);
    return "application/octet-stream";
}

std::optional<std::string> query_value(std::string_view query, std::string_view key) {
    while (!query.empty()) {
        const std::size_t amp = query.find('&');
        const std::string_view pair = query.substr(0, amp);
        query = amp == std::string_view::npos ? std::string_view() : query.substr(amp + 1);
        const std::size_t eq = pair.find('=');
        if (pair.substr(0, eq) != key) continue;
        return eq == std::string_view::npos ? std::string() : percent_decode(pair.substr(eq + 1));
    }
    return std::nullopt;
}

std::string datasets_json(const std::vector<std::string>& names, bool token_required) {
    std::string out = "{\"datasets\":[";
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (i > 0) out += ',';
        append_json_string(out, names[i]);
    }
    out += "],\"token_required\":";
    out += token_required ? "true}" : "false}";
    return out;
}

web::HttpResponse route(const web::HttpRequest& request, const RouteContext& context) {
    if (request.method != "GET") return text(405, "only GET is served here");
    if (request.path == "/datasets") return datasets(request, context);
    const std::string_view name =
        request.path == "/" ? context.index : std::string_view(request.path);
    const WebAsset* asset =
        find_asset(context.assets, name.starts_with('/') ? name.substr(1) : name);
    if (!asset) return text(404, "not found: " + request.path);
    return {200, content_type_for(asset->name),
            std::string(reinterpret_cast<const char*>(asset->bytes.data()), asset->bytes.size())};
}

}  // namespace isowall::remote
