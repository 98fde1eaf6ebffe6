// Writes the view_protocol harness's seed corpus: each message of the remote-viewing protocol with
// every field set, once as a payload (mode byte 0, the type, the payload) and once as a frame on a
// stream (mode byte 1, a chunk seed, the frame), plus one stream of every message in a row.
// Run: fuzz_view_protocol_seeds fuzz/corpus/view_protocol (the files there are its output,
// committed).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "remote/view_framing.h"

namespace {

using namespace isowall;
using namespace isowall::remote;

std::vector<RemoteMessage> samples() {
    RequestMsg request;
    request.request_id = 3;
    request.view.camera.eye = {1, -40, 3};
    request.view.frustum.left = -0.5f;
    request.view.width = 8;
    request.view.height = 6;
    request.view.iso = 105.5;
    request.lod = LodSchedule::chosen;
    request.cached_groups = true;
    const GroupKey key{{4, 5, 6}, 2, 105.5, true};
    return {
        HelloMsg{1, "ct_head", "s3cret", 2, SessionRole::none, ""},
        ReadyMsg{{{0, 0, 0}, {1, 2, 3}},
                 -1024,
                 3071,
                 {256, 256, 113},
                 {1, 1, 2},
                 glm::mat3(glm::vec3(0, 1, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1))},
        request,
        GroupMsg{3, key, true, 3, {std::byte{1}, std::byte{2}, std::byte{3}}},
        VisibleMsg{3, {0, 1, 2, 5, 7, 11}},  // a bitmap; the deltas form is in the fuzzer's reach
        EndOfFrameMsg{3, 480000, 120, 90000, 2400000},
        make_error(ErrorCode::bad_token, "wrong token"),
        ByeMsg{},
        SessionMsg{"class 3b", "10.0.0.7:51234", 12},
        DecodeRateMsg{{{3, 120000, 0.0125}, {4, 30000, 0.01}}},
        ExactMsg{3, key, {std::byte{0x5a}, std::byte{0x81}}}};
}

bool write(const std::filesystem::path& path, const std::vector<std::byte>& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
    if (!out) std::fprintf(stderr, "fuzz_view_protocol_seeds: cannot write %s\n", path.c_str());
    return static_cast<bool>(out);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: fuzz_view_protocol_seeds FOLDER\n");
        return 2;
    }
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    std::vector<std::byte> all{std::byte{1}, std::byte{5}};
    int n = 0;
    for (const RemoteMessage& m : samples()) {
        const auto type = static_cast<std::uint16_t>(type_of(m));
        std::vector<std::byte> payload{std::byte{0}, std::byte(type & 0xff), std::byte(type >> 8)};
        const auto p = encode_payload(m);
        payload.insert(payload.end(), p.begin(), p.end());
        std::vector<std::byte> stream{std::byte{1}, std::byte(n)};
        const auto f = encode_frame(m);
        stream.insert(stream.end(), f.begin(), f.end());
        all.insert(all.end(), f.begin(), f.end());
        const std::string name = to_string(type_of(m));
        if (!write(dir / ("payload-" + name), payload) || !write(dir / ("stream-" + name), stream))
            return 1;
        ++n;
    }
    if (!write(dir / "stream-all", all)) return 1;
    std::printf("fuzz_view_protocol_seeds: %d messages in %s\n", n, dir.c_str());
    return 0;
}
