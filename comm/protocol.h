#pragma once
// Every message between the ranks of a wall run: one typed struct per message, each with its tag
// and version; encode and decode live side by side in protocol.cpp. Decoding checks every length,
// count, enum and size against the bytes and the limits below and throws WireError on anything
// malformed, truncated, of another version or with trailing bytes.
#include <cstdint>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "common/core/view.h"
#include "common/core/wire.h"
#include "common/progressive/trace.h"

namespace isowall {

// The MPI tag of each message. 16..31 are kept for the screen-region scheduler's job messages.
enum class Tag : std::int32_t {
    hello = 1,        // tile -> master, first thing: its host name
    view = 2,         // master -> tile: a new frame (interrupts the current one)
    progress = 3,     // tile -> master: rays cast so far in a frame
    snapshot = 4,     // master -> tile: send the image being built
    image = 5,        // tile -> master: an image (a snapshot answer, or the final one after quit)
    quit = 6,         // master -> tile: send the result and the final image, then stop
    tile_result = 7,  // tile -> master: a tile's figures and trace, its last message but the image
};
inline constexpr Tag kLastTag = Tag::tile_result;
const char* to_string(Tag tag);

// Largest image side a message may carry. A message over 2 GiB cannot travel (MPI counts are int);
// a tile is far smaller (a 4K display is 32 MiB of RGBA).
inline constexpr int kMaxImageSide = 32768;

struct HelloMsg {
    static constexpr Tag kTag = Tag::hello;
    static constexpr std::uint8_t kVersion = 1;
    std::string host;
};

struct ViewMsg {
    static constexpr Tag kTag = Tag::view;
    static constexpr std::uint8_t kVersion = 2;
    std::uint64_t generation = 0;  // grows with every change of camera or isovalue
    FrameView view;
    PixelRect region;  // the pixels of view's screen to fill (a whole tile today)
};

struct ProgressMsg {
    static constexpr Tag kTag = Tag::progress;
    static constexpr std::uint8_t kVersion = 2;
    std::uint64_t generation = 0;
    std::uint64_t rays = 0;
    bool done = false;  // the frame has cast its last ray
    double cpu_s = 0;   // the frame thread's CPU seconds into the frame (emulated time)
};

struct SnapshotMsg {
    static constexpr Tag kTag = Tag::snapshot;
    static constexpr std::uint8_t kVersion = 1;
};

struct ImageMsg {
    static constexpr Tag kTag = Tag::image;
    static constexpr std::uint8_t kVersion = 2;
    std::uint64_t generation = 0;
    std::int32_t width = 0, height = 0;
    std::vector<std::uint8_t> rgba;  // width * height * 4, row 0 at the top
    std::vector<float> depth;        // empty, or width * height window depths (1 = background)
};

struct QuitMsg {
    static constexpr Tag kTag = Tag::quit;
    static constexpr std::uint8_t kVersion = 1;
};

struct TileResultMsg {
    static constexpr Tag kTag = Tag::tile_result;
    static constexpr std::uint8_t kVersion = 2;
    std::string host;
    double cpu_s = 0;    // the frame thread's CPU seconds, all frames
    double frame_s = 0;  // wall seconds of all frames
    double rss_mib = 0;
    std::uint64_t rays = 0, groups = 0, triangles = 0, frames = 0, interrupted = 0;
    std::vector<TraceSpan> spans;
};

using Message =
    std::variant<HelloMsg, ViewMsg, ProgressMsg, SnapshotMsg, ImageMsg, QuitMsg, TileResultMsg>;

std::vector<std::byte> encode(const HelloMsg& m);
std::vector<std::byte> encode(const ViewMsg& m);
std::vector<std::byte> encode(const ProgressMsg& m);
std::vector<std::byte> encode(const SnapshotMsg& m);
std::vector<std::byte> encode(const ImageMsg& m);
std::vector<std::byte> encode(const QuitMsg& m);
std::vector<std::byte> encode(const TileResultMsg& m);
std::vector<std::byte> encode(const Message& m);
Tag tag_of(const Message& m);

// Throws WireError naming the message and the fault; an unknown tag is an error too.
Message decode_message(Tag tag, std::span<const std::byte> bytes);

// The message as T; a message of another kind is a WireError ("expected view, got image").
template <class T>
T decode_as(Tag tag, std::span<const std::byte> bytes) {
    if (tag != T::kTag)
        throw WireError(std::string("expected a ") + to_string(T::kTag) + " message, got " +
                        to_string(tag));
    return std::get<T>(decode_message(tag, bytes));
}

}  // namespace isowall
