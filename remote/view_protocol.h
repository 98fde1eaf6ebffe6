#pragma once
// The messages between `isowall serve` and `isowall view`: one typed struct per
// message, encode and decode side by side in view_protocol.cpp. A payload starts with its layout
// version byte (MessageWriter), then the fields, little-endian. Decoding checks every value, not
// only lengths (finite numbers, enum ranges, bounded printable text, counts against the bytes
// left before anything is allocated, no trailing bytes) and throws WireError naming the message
// and the field, so a message that decodes is one the receiver can use as is. The framing of
// these payloads on a byte stream is in view_framing.h.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "core/box.h"
#include "core/view.h"
#include "extract/group.h"
#include "wire/wire.h"

namespace isowall::remote {

// The type field of a frame's header. Numbers are never reused: a retired type stays retired.
enum class RemoteTag : std::uint16_t {
    hello = 1,         // client -> server, first: protocol version, dataset, token, encoding
    ready = 2,         // server -> client: the dataset is loaded; its bounds and range
    request = 3,       // client -> server: a view to draw; interrupts the current one
    group = 4,         // server -> client: one encoded group of a request
    visible = 5,       // server -> client: cached groups the request's view sees
    end_of_frame = 6,  // server -> client: the request is complete; its figures
    error = 7,         // either way: what was wrong; the sender closes the connection after it
    bye = 8,           // either way: the sender closes the connection, nothing was wrong
    session = 9,       // server -> a shared session's members: its name, presenter and size
    decode_rate = 10,  // client -> server: what decoding groups cost the client (adaptive only)
    exact = 11,        // server -> client: a group's exact values, after it went to a step
};
inline constexpr std::uint16_t kLastRemoteTag = 11;
const char* to_string(RemoteTag type);

// ---- limits: each is checked by the decoder before anything is sized from the bytes -----------
inline constexpr std::size_t kMaxDatasetNameBytes = 256;  // printable ASCII, not empty
inline constexpr std::size_t kMaxTokenBytes = 256;        // printable ASCII, may be empty
inline constexpr std::size_t kMaxErrorTextBytes = 256;    // one printable ASCII line
inline constexpr std::size_t kMaxSessionNameBytes = 64;   // printable ASCII
inline constexpr std::size_t kMaxPeerNameBytes = 128;     // printable ASCII ("ADDR:PORT")
// An encoded group. Groups of the default propagation (1000 cells) take a few hundred KiB; the
// bound keeps every valid group message under the framing's default payload limit (64 MiB).
inline constexpr std::size_t kMaxGroupBytes = std::size_t{32} << 20;
// Slots of a generation's cached groups (VisibleMsg): each below this, so a bitmap is <= 128 KiB.
inline constexpr std::size_t kMaxVisibleKeys = std::size_t{1} << 20;
// A group's level: meta-cells of 2^level cells per side, so anything past 30 overflows an int.
inline constexpr int kMaxGroupLevel = 30;

// A shared session (view --present / --follow NAME): the presenter's requests are extracted once
// and streamed to every member; a follower sends no request, and gets each of the presenter's
// as a RequestMsg from the server, before its groups.
enum class SessionRole : std::uint8_t { none = 0, presenter = 1, follower = 2 };

struct HelloMsg {
    static constexpr RemoteTag kTag = RemoteTag::hello;
    // 2: session and role. 3: takes_exact too. Encoded in the oldest layout that holds what is
    // set (1 without a role or takes_exact, 2 with a role alone), so a client that asks for
    // neither speaks to servers of version 1; all three decode.
    static constexpr std::uint8_t kVersion = 3;
    std::uint16_t protocol_version = 1;  // the newest the client speaks
    std::string dataset;                 // the name the server loaded the volume under
    std::string token;                   // empty unless the server asks for one (--token)
    std::uint8_t encoding = 0;           // the group encoding the client wants (remote codec's id)
    SessionRole role = SessionRole::none;
    std::string session;  // with a role: 1..kMaxSessionNameBytes printable ASCII; else empty
    // The client takes ExactMsg: a cells group's gradient voxels may come to a step first and
    // their exact values after (remote/cell_codec.h). A client that does not say so gets every
    // group exact.
    bool takes_exact = false;
};

// Sent to every member of a shared session when one joins or leaves.
struct SessionMsg {
    static constexpr RemoteTag kTag = RemoteTag::session;
    static constexpr std::uint8_t kVersion = 1;
    std::string session;        // its name
    std::string presenter;      // who presents ("ADDR:PORT"), empty while nobody does
    std::uint32_t members = 0;  // presenter included
};

struct ReadyMsg {
    static constexpr RemoteTag kTag = RemoteTag::ready;
    // 2: axes, so a client's front view is the patient's front (version 1 had none).
    static constexpr std::uint8_t kVersion = 2;
    Box3 bounds{glm::vec3(0), glm::vec3(1)};  // object space; finite, min <= max
    double value_min = 0, value_max = 0;      // finite, min <= max
    glm::ivec3 dims{1};                       // samples per axis, each >= 1
    glm::vec3 spacing{1};                     // finite, each > 0
    // The volume's axes in patient space (volume/volume.h: Orientation): finite unit
    // columns making a rotation, identity when the file gave none.
    glm::mat3 axes{1.0f};
};

// Progressive LOD for a request (the dissertation's section 4.1.3, case 3): coarse passes at
// meta-cells of 4 and 2 cells a side before the full resolution, never, or where the server
// forecasts that they bring C = 90% sooner (remote/lod_choice.h; `isowall view`'s and the page's
// default).
enum class LodSchedule : std::uint8_t { off = 0, on = 1, chosen = 2 };
std::string to_string(LodSchedule s);

struct RequestMsg {
    static constexpr RemoteTag kTag = RemoteTag::request;
    // 2: the lod byte may be 2 (chosen), which version 1 had as a flag.
    static constexpr std::uint8_t kVersion = 2;
    std::uint64_t request_id = 0;  // grows with every request of a connection
    // Camera, frustum, image size (each side 1..kMaxImageSide) and isovalue; the camera and the
    // frustum must be ones that can be drawn (camera_problem and frustum_problem are empty). The
    // server checks the isovalue against the dataset's range (request_checks.h).
    FrameView view;
    LodSchedule lod = LodSchedule::off;
    bool cached_groups = false;  // case 4: the client caches groups per isovalue
};

struct GroupMsg {
    static constexpr RemoteTag kTag = RemoteTag::group;
    static constexpr std::uint8_t kVersion = 2;
    std::uint64_t request_id = 0;
    GroupKey key;  // seed >= 0 on each axis, level 0..kMaxGroupLevel, finite iso
    // A late coarse group (section 4.1.4): cached now, drawn only from the next frame.
    bool draw_from_next_frame = false;
    // 0: the client does not cache the group. Otherwise the server's cache generation (the id of
    // the request that began it): a client holding another generation drops it and begins this
    // one, then appends the group, whose slot (VisibleMsg) is its index in the generation. The
    // server decides, as only it knows which requests it skipped.
    std::uint64_t cache_gen = 0;
    std::vector<std::byte> encoded;  // the group in the hello's encoding; <= kMaxGroupBytes
};

struct VisibleMsg {
    static constexpr RemoteTag kTag = RemoteTag::visible;
    static constexpr std::uint8_t kVersion = 2;
    std::uint64_t request_id = 0;
    // Cached groups of the client's generation, by slot: strictly ascending, each below
    // kMaxVisibleKeys; a bitmap or deltas on the wire, whichever is smaller (slot_list.h).
    std::vector<std::uint32_t> slots;
};

struct EndOfFrameMsg {
    static constexpr RemoteTag kTag = RemoteTag::end_of_frame;
    static constexpr std::uint8_t kVersion = 1;
    std::uint64_t request_id = 0;
    std::uint64_t rays = 0, groups = 0, triangles = 0;
    std::uint64_t bytes = 0;  // of every frame the server sent for this request, headers included
};

enum class ErrorCode : std::uint16_t {
    malformed = 1,            // a message did not decode (the text says which field)
    unsupported_version = 2,  // the header's or hello's protocol version
    bad_token = 3,
    unknown_dataset = 4,
    too_large = 5,  // a frame's payload over the receiver's limit
    internal = 6,   // the sender failed (loading, extracting); the text says how
    session = 7,    // a shared session refused the hello, or dropped a follower; the text says why
};
inline constexpr std::uint16_t kLastErrorCode = 7;

struct ErrorMsg {
    static constexpr RemoteTag kTag = RemoteTag::error;
    static constexpr std::uint8_t kVersion = 1;
    ErrorCode code = ErrorCode::malformed;
    std::string text;  // one printable ASCII line, <= kMaxErrorTextBytes
};
// An ErrorMsg that encodes to a valid message whatever `text` holds: cut to kMaxErrorTextBytes,
// every byte outside printable ASCII (a newline, UTF-8) replaced by '?'.
ErrorMsg make_error(ErrorCode code, std::string_view text);

// What decoding the groups cost the client since its last report, per encoding (the
// adaptive server weighs the client's decoding beside its own work and the link). Sent by a
// client that asked for the server's choice (hello encoding kAdaptiveEncoding), every few groups.
struct DecodeRateMsg {
    static constexpr RemoteTag kTag = RemoteTag::decode_rate;
    static constexpr std::uint8_t kVersion = 1;
    struct Entry {
        std::uint8_t encoding = 0;    // a group codec's id, < kDecodeRateEncodings; ascending
        std::uint64_t triangles = 0;  // decoded
        double seconds = 0;           // spent decoding them: finite, >= 0
    };
    std::vector<Entry> entries;  // at most one per encoding
};
// The group codecs (remote/group_codec.h: GroupEncoding's count; encoding_choice.h checks it).
inline constexpr unsigned kDecodeRateEncodings = 5;

// A cells group's exact values (remote/cell_exact.h), after its GroupMsg of the same request and
// key sent its gradients' voxels to a step; only to a client whose hello said takes_exact, only
// for a group it does not cache, before the request's EndOfFrameMsg. The client decodes the group
// again with them, and draws the exact mesh in place of the stepped one.
struct ExactMsg {
    static constexpr RemoteTag kTag = RemoteTag::exact;
    static constexpr std::uint8_t kVersion = 1;
    std::uint64_t request_id = 0;
    GroupKey key;                 // as GroupMsg's
    std::vector<std::byte> bits;  // <= kMaxGroupBytes
};

struct ByeMsg {
    static constexpr RemoteTag kTag = RemoteTag::bye;
    static constexpr std::uint8_t kVersion = 1;
};

using RemoteMessage =
    std::variant<HelloMsg, ReadyMsg, RequestMsg, GroupMsg, VisibleMsg, EndOfFrameMsg, ErrorMsg,
                 ByeMsg, SessionMsg, DecodeRateMsg, ExactMsg>;

// The payload of a message (what follows the frame header).
std::vector<std::byte> encode_payload(const RemoteMessage& m);
RemoteTag type_of(const RemoteMessage& m);
// Throws WireError naming the message and the field; an unknown type is an error too.
RemoteMessage decode_payload(RemoteTag type, std::span<const std::byte> payload);

}  // namespace isowall::remote
