#include "master/wall_page.h"

#include <zstd.h>

#include <cstring>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "wall_spec/script.h"
#include "wire/wire.h"

namespace isowall {
namespace {

using nlohmann::json;

constexpr char kMosaicMagic[4] = {'I', 'W', 'M', '1'};
constexpr std::size_t kMosaicHeader = 4 + 4 + 4 + 8;

void put_le(std::string& out, std::uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

std::uint64_t get_le(std::string_view in, std::size_t at, int bytes) {
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i)
        v |= std::uint64_t(static_cast<unsigned char>(in[at + static_cast<std::size_t>(i)]))
             << (8 * i);
    return v;
}

// The string value of a field of a page's message.
std::string string_field(const json& value, const std::string& who, const char* field) {
    if (!value.is_string())
        throw InputError(who, field, std::string("expected a string after \"") + field + "\"");
    return value.get<std::string>();
}

void check_page_command(const std::string& line, const std::string& who) {
    const ScriptCommand cmd = parse_command(line, who);
    if (std::holds_alternative<WaitCmd>(cmd))
        throw InputError(who, "run", "wait is not a page command: a page never stalls the wall");
    if (std::holds_alternative<SnapshotCmd>(cmd))
        throw InputError(who, "run",
                         "snapshot takes no name from a page: send {\"snapshot\": true}");
}

}  // namespace

PageMessage parse_page_message(std::string_view bytes, const std::string& who) {
    if (bytes.size() > kMaxPageMessage)
        throw InputError(who, "message",
                         "longer than " + std::to_string(kMaxPageMessage) + " bytes");
    const json j = json::parse(bytes, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded() || !j.is_object() || j.size() != 1)
        throw InputError(who, "message",
                         "expected one of {\"hello\": TOKEN}, {\"run\": LINE}, "
                         "{\"snapshot\": true}, {\"take\": true}, got " +
                             quote(std::string(bytes.substr(0, 80))));
    // The key and value through an iterator of `j` itself: items() is a temporary view, and a
    // binding to its element outlived it (the fuzzer's ASan build caught the read).
    const auto first = j.begin();
    const std::string key = first.key();
    const json& value = first.value();
    PageMessage m;
    if (key == "hello") {
        m.kind = PageMessage::Kind::hello;
        m.text = string_field(value, who, "hello");
    } else if (key == "run") {
        m.kind = PageMessage::Kind::run;
        m.text = string_field(value, who, "run");
        check_page_command(m.text, who);
    } else if (key == "snapshot" || key == "take") {
        if (value != true) throw InputError(who, key, "expected true");
        m.kind = key == "take" ? PageMessage::Kind::take : PageMessage::Kind::snapshot;
    } else {
        throw InputError(who, "message",
                         "unknown field " + quote(key) + " (expected hello, run, snapshot, take)");
    }
    return m;
}

bool SteeringSeat::claim(std::uint64_t id) {
    if (!holder_) holder_ = id;
    return *holder_ == id;
}

void SteeringSeat::leave(std::uint64_t id) {
    if (holder_ == id) holder_.reset();
}

std::string welcome_json(const std::string& you, const ControlLayout& layout,
                         const std::string& wall_name) {
    json tiles = json::array();
    for (const PixelRect& r : layout.tiles) tiles.push_back({r.x, r.y, r.width, r.height});
    return json{{"type", "welcome"},
                {"you", you},
                {"wall", wall_name},
                {"width", layout.mosaic.width},
                {"height", layout.mosaic.height},
                {"tiles", tiles}}
        .dump(-1, ' ', false, json::error_handler_t::replace);
}

namespace {

// The page's legend: its title, the ends of the range and nine colours from the low end to the
// high one (a CSS gradient through them shows the map); null when the surface has one colour.
json legend_json(const PageState& s) {
    if (!s.legend.map.table) return nullptr;
    json stops = json::array();
    for (int i = 0; i <= 8; ++i) {
        const glm::u8vec3 c = s.legend.map.at(i / 8.0);
        char hex[8];
        std::snprintf(hex, sizeof(hex), "#%02x%02x%02x", c.x, c.y, c.z);
        stops.push_back(hex);
    }
    return {{"label", s.legend_label}, {"lo", s.legend.lo}, {"hi", s.legend.hi}, {"stops", stops}};
}

}  // namespace

std::string state_json(const PageState& s) {
    const FrameFigures& f = s.figures;
    return json{{"type", "state"},          {"iso", s.iso},
                {"value_min", s.value_min}, {"value_max", s.value_max},
                {"frame", s.frame},         {"done", s.done},
                {"frame_s", s.frame_s},     {"emulated_s", f.emulated_s},
                {"balance", f.balance},     {"jobs", f.jobs},
                {"jobs_done", f.jobs_done}, {"migrated", f.migrated},
                {"c99_s", f.c99_s},         {"steering", s.steering},
                {"pages", s.pages},         {"dark", s.dark},
                {"clip", s.clip},           {"dims", {s.dims.x, s.dims.y, s.dims.z}},
                {"surfaces", s.surfaces},   {"steps", s.steps},
                {"step", s.step},           {"playing", s.playing},
                {"legend", legend_json(s)}}
        .dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string ran_json(const std::string& who, const std::string& line, const std::string& error) {
    return json{{"type", "ran"}, {"who", who}, {"line", line}, {"error", error}}.dump(
        -1, ' ', false, json::error_handler_t::replace);
}

std::string error_json(const std::string& text) {
    return json{{"type", "error"}, {"text", text}}.dump(-1, ' ', false,
                                                        json::error_handler_t::replace);
}

std::string encode_mosaic(const Image& mosaic, std::uint64_t frame) {
    std::vector<std::uint8_t> rgb(mosaic.pixel_count() * 3);
    for (std::size_t i = 0; i < mosaic.pixel_count(); ++i)
        std::memcpy(&rgb[i * 3], &mosaic.rgba[i * 4], 3);
    std::string out(kMosaicMagic, sizeof(kMosaicMagic));
    put_le(out, static_cast<std::uint32_t>(mosaic.width), 4);
    put_le(out, static_cast<std::uint32_t>(mosaic.height), 4);
    put_le(out, frame, 8);
    const std::size_t bound = ZSTD_compressBound(rgb.size());
    out.resize(kMosaicHeader + bound);
    // Level 1: a mosaic goes out up to ten times a second; black backgrounds compress anyway.
    const std::size_t n =
        ZSTD_compress(out.data() + kMosaicHeader, bound, rgb.data(), rgb.size(), 1);
    if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
    out.resize(kMosaicHeader + n);
    return out;
}

Image decode_mosaic(std::string_view bytes, std::uint64_t* frame) {
    if (bytes.size() < kMosaicHeader || std::memcmp(bytes.data(), kMosaicMagic, 4) != 0)
        throw WireError("mosaic: not an IWM1 message");
    const std::uint64_t w = get_le(bytes, 4, 4), h = get_le(bytes, 8, 4);
    if (w < 1 || h < 1 || w > 4096 || h > 4096)
        throw WireError("mosaic: size " + std::to_string(w) + "x" + std::to_string(h));
    if (frame) *frame = get_le(bytes, 12, 8);
    const std::string_view packed = bytes.substr(kMosaicHeader);
    const unsigned long long size = ZSTD_getFrameContentSize(packed.data(), packed.size());
    if (size != w * h * 3) throw WireError("mosaic: the pixels are not width x height x 3 bytes");
    std::vector<std::uint8_t> rgb(size);
    const std::size_t n = ZSTD_decompress(rgb.data(), rgb.size(), packed.data(), packed.size());
    if (ZSTD_isError(n) || n != size) throw WireError("mosaic: the pixels do not decompress");
    Image img;
    img.width = static_cast<int>(w);
    img.height = static_cast<int>(h);
    img.rgba.assign(img.pixel_count() * 4, 255);
    for (std::size_t i = 0; i < img.pixel_count(); ++i)
        std::memcpy(&img.rgba[i * 4], &rgb[i * 3], 3);
    return img;
}

}  // namespace isowall
