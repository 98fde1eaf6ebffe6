#pragma once
// Every message between the ranks of a wall run: one typed struct per message, each with its tag
// and version; encode and decode live side by side in protocol.cpp. Decoding checks every length,
// count, enum and size against the bytes and the limits below and throws WireError on anything
// malformed, truncated, of another version or with trailing bytes.
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "comm/comm.h"
#include "core/preview.h"
#include "core/surface_style.h"
#include "core/view.h"
#include "progressive/trace.h"
#include "wall_spec/wall.h"  // kMasterRank: the rank the messages go to and come from
#include "wire/wire.h"

namespace isowall {

// The MPI tag of each message. 16..31 are the screen-region scheduler's job messages.
enum class Tag : std::int32_t {
    hello = 1,        // tile -> master: its host name, once joined and again once loaded
    view = 2,         // master -> tile: a new frame (interrupts the current one); jobs follow
    progress = 3,     // tile -> master: rays cast so far in a frame
    snapshot = 4,     // master -> tile: send the image being built
    image = 5,        // tile -> master: an image (a snapshot answer, or the final one after quit)
    quit = 6,         // master -> tile: send the result and the final image, then stop
    tile_result = 7,  // tile -> master: a tile's figures and trace, its last message but the image
    release = 8,      // master -> tile: every rank has sent its result; exit now
    start = 9,        // master -> tile: the volume and its octree cache are ready; load them
    alive = 10,       // both ways, every kAliveIntervalS: the sender's message loop is running
    preview = 11,     // tile -> master (--control): a small copy of what the tile shows now
    store_ask = 12,   // tile -> master: a part of the master's store (its host cannot see it)
    store_meta = 13,  // master -> tile: the store's metadata (the answer to a meta ask)
    store_part = 14,  // master -> tile: the store's octree piece or chunk that was asked for
    job = 16,         // master -> worker: fill a screen region of a tile (its own or another's)
    job_done = 17,    // worker -> master: the job's figures; the worker is free for the next
    region = 18,      // worker -> owner: colour and depth of a region it filled for the owner
    landed = 19,      // owner -> master: a helper's region result has been composited
    curve_ask = 20,   // master -> tile (--measure): the frame is complete; send its curve
    curve = 21,       // tile -> master: that frame's correctness curve (the page's C = 99%)
    failed = 22,      // tile -> master: the rank has failed; the master says why, once, and ends
    lost = 23,        // master -> tile: a tile rank is gone; never send to it again
};
const char* to_string(Tag tag);

// A tile says hello twice: as soon as it has joined the job (loaded = false), and once it has
// loaded the volume and can take views (loaded = true). The master names the tiles it has not
// heard from when a stage of the start-up runs past --startup-timeout.
struct TileHelloMsg {
    static constexpr Tag kTag = Tag::hello;
    static constexpr std::uint8_t kVersion = 3;
    std::string host;
    std::uint32_t threads = 1;  // the rank's engine threads (its thread budget)
    bool loaded = false;
};

struct ViewMsg {
    static constexpr Tag kTag = Tag::view;
    static constexpr std::uint8_t kVersion = 5;  // 3: clip planes; 4: surfaces; 5: time step
    std::uint64_t generation = 0;  // grows with every change of camera, isovalue or clip
    FrameView view;                // the tile's own view; its pixels come as jobs
    // The surfaces drawn together (core/surface_style.h, canonical order); view.iso is the first's.
    // Empty: one plain surface at view.iso.
    std::vector<SurfaceStyle> surfaces{};
    std::uint32_t step = 0;  // the time step of a series (volume/time_steps.h); 0 otherwise
};

struct ProgressMsg {
    static constexpr Tag kTag = Tag::progress;
    static constexpr std::uint8_t kVersion = 3;
    std::uint64_t generation = 0;
    std::uint64_t rays = 0;  // cast by this rank in this frame, for any tile
    double cpu_s = 0;        // the frame thread's CPU seconds into the frame (emulated time)
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

// One point of a tile's correctness curve against emulated time (the last frame): what its
// display showed once the jobs that ended by `emulated_s` had landed, as sums, so that the
// master can add the tiles' sums into wall-wide measures.
struct CurvePoint {
    double emulated_s = 0;       // the CPU clock of the worker whose job ended here
    std::uint64_t final_px = 0;  // significant pixels with their final colour
    double squared_error = 0;    // sum over significant pixels of e(P)^2
};

// A frame before the last, measured (--measure) on one tile: its curve against that frame's final
// image, kept when the next view came (the master uses those of frames it knows were complete).
struct FrameCurve {
    std::uint64_t generation = 0;
    std::uint64_t significant = 0;
    std::vector<CurvePoint> points;
};

struct TileResultMsg {
    static constexpr Tag kTag = Tag::tile_result;
    static constexpr std::uint8_t kVersion = 5;
    std::string host;
    double cpu_s = 0;    // the frame thread's CPU seconds, all frames
    double frame_s = 0;  // wall seconds of all frames
    double rss_mib = 0;
    std::uint64_t rays = 0, groups = 0, triangles = 0, frames = 0, interrupted = 0;
    std::uint64_t jobs_own = 0, jobs_helped = 0;  // jobs run for its own tile and for others
    std::uint64_t bytes_sent = 0;                 // region results sent to other tiles
    std::uint64_t late_dropped = 0;   // helpers' results of a view already replaced, dropped
    std::uint64_t significant = 0;    // covered pixels of the last frame's final image
    std::vector<CurvePoint> curve;    // empty unless measured (--measure)
    std::vector<FrameCurve> earlier;  // the earlier frames' curves (--measure)
    std::vector<TraceSpan> spans;
};

struct ReleaseMsg {
    static constexpr Tag kTag = Tag::release;
    static constexpr std::uint8_t kVersion = 1;
};

struct StartMsg {
    static constexpr Tag kTag = Tag::start;
    static constexpr std::uint8_t kVersion = 1;
};

// Liveness: a rank whose peer has sent nothing, not even this, for --timeout seconds ends the job
// naming that peer (stopped, killed without a word, or on a host that cannot be reached).
inline constexpr double kAliveIntervalS = 0.5;
struct AliveMsg {
    static constexpr Tag kTag = Tag::alive;
    static constexpr std::uint8_t kVersion = 1;
};

// With --control, each tile sends the master a scaled-down copy of what it shows
// (core/preview.h: make_preview) while a frame builds and when it ends; the master's control
// window shows them as a live mosaic of the wall.
struct PreviewMsg : Preview {
    static constexpr Tag kTag = Tag::preview;
    static constexpr std::uint8_t kVersion = 1;
};

// A tile rank whose host cannot see the store given as --volume (a display node without the
// shared file system) asks the master for it (tile/remote_bricks.h): first its metadata, then its
// octree file in pieces, then, while frames run, the compressed chunks its pager needs. The
// master reads them from its own copy and sends them as they are on disk; the tile checks each
// chunk as if it had read it (checksum, size).
enum class StorePart : std::uint8_t { meta = 0, octree = 1, chunk = 2 };
inline constexpr std::uint64_t kOctreePieceBytes = std::uint64_t(16) << 20;
// The most a store_part carries: a chunk of the largest brick (64^3 float64 voxels, 2 MiB) never
// compresses past it, and an octree piece is kOctreePieceBytes.
inline constexpr std::uint64_t kMaxStorePartBytes = std::uint64_t(32) << 20;

struct StoreAskMsg {
    static constexpr Tag kTag = Tag::store_ask;
    static constexpr std::uint8_t kVersion = 1;
    StorePart part = StorePart::meta;
    std::uint64_t index = 0;  // the octree piece, or the chunk's brick (x fastest); 0 for meta
};

struct StoreMetaMsg {
    static constexpr Tag kTag = Tag::store_meta;
    static constexpr std::uint8_t kVersion = 1;
    bool is_store = false;       // false: the master's volume is not a store, so it cannot be sent
    std::string zarray, zattrs;  // the store's 0/.zarray and .zattrs, as on disk
    std::uint64_t octree_bytes = 0;   // the size of its octree file (sent in pieces)
    std::uint64_t bytes_on_disk = 0;  // its chunks' compressed bytes, for `info` lines
};

struct StorePartMsg {
    static constexpr Tag kTag = Tag::store_part;
    static constexpr std::uint8_t kVersion = 1;
    StorePart part = StorePart::chunk;  // octree or chunk
    std::uint64_t index = 0;
    std::vector<std::byte> bytes;  // at most kMaxStorePartBytes
};

// Which ray-order levels of a region a job casts: the coarse levels (until about 1/16 of the
// region's rays) or the rest. Coarse jobs of every tile go before fine jobs anywhere.
enum class Band : std::uint8_t { coarse = 0, fine = 1 };

struct JobMsg {
    static constexpr Tag kTag = Tag::job;
    static constexpr std::uint8_t kVersion = 3;  // 3: the view's clip planes
    std::uint64_t generation = 0;
    std::uint32_t job = 0;   // the master's id, unique within a generation
    std::int32_t owner = 0;  // the rank whose tile the region is on
    // Where a helper sends the region's result: the owner, or the master when the owner is lost
    // (the master then composes the lost tile's screen itself).
    std::int32_t deliver = 0;
    Band band = Band::coarse;
    FrameView view;  // the owner's view
    PixelRect rect;  // in the owner's screen; not empty
};

struct JobDoneMsg {
    static constexpr Tag kTag = Tag::job_done;
    static constexpr std::uint8_t kVersion = 1;
    std::uint64_t generation = 0;
    std::uint32_t job = 0;
    std::uint64_t rays = 0, groups = 0, triangles = 0;
    double cpu_s = 0;      // the job's thread CPU seconds
    double cpu_end_s = 0;  // the worker's thread CPU seconds into the frame when the job ended
    double start_s = 0, end_s = 0;  // wall clock (trace time base)
    std::uint64_t bytes = 0;        // the region result sent to the owner (0 for its own)
};

struct RegionMsg {
    static constexpr Tag kTag = Tag::region;
    static constexpr std::uint8_t kVersion = 2;  // 2: the layer
    std::uint64_t generation = 0;
    std::uint32_t job = 0;
    std::uint8_t layer = 0;  // which of the view's surfaces (ViewMsg::surfaces) it shows
    PixelRect rect;          // in the owner's screen; rgba and depth are its pixels
    double cpu_end_s = 0;    // the helper's emulated time at the end of the job
    std::vector<std::uint8_t> rgba;
    std::vector<float> depth;
};

// A region result's pixels as an image of its rect's size (colour and depth, moved out of `m`),
// for composite_by_depth into the screen at m.rect; a rect outside a width x height screen is a
// WireError naming the message.
Image region_image(RegionMsg&& m, int width, int height);

struct LandedMsg {
    static constexpr Tag kTag = Tag::landed;
    static constexpr std::uint8_t kVersion = 1;
    std::uint64_t generation = 0;
    std::uint32_t job = 0;
};

// With --measure, once every job of a frame has landed, the master asks each tile for the frame's
// curve (its shown image is then final) and merges them into the wall's C = 99% while the wall
// runs (app/wall_http.h shows it). A tile whose frame is another answers nothing.
struct CurveAskMsg {
    static constexpr Tag kTag = Tag::curve_ask;
    static constexpr std::uint8_t kVersion = 1;
    std::uint64_t generation = 0;
};

struct CurveMsg {
    static constexpr Tag kTag = Tag::curve;
    static constexpr std::uint8_t kVersion = 1;
    FrameCurve curve;  // its generation is the frame's
};

// A tile rank's error, sent to the master instead of printed: the master prints the first it
// hears of as the job's one error line and ends every rank, so tiles that fail together (a
// damaged chunk that each of them meets) give one line, not one per tile.
struct FailedMsg {
    static constexpr Tag kTag = Tag::failed;
    static constexpr std::uint8_t kVersion = 1;
    bool input = false;  // bad input (it names its source), not an error of the rank itself
    std::string what;    // at most kMaxFailedBytes
};
inline constexpr std::uint64_t kMaxFailedBytes = 4096;

// A tile's error that says the master cannot hear it (silent, or not yet listening): the tile
// says it itself rather than sending a failed message that nobody would read.
class MasterUnreachable : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// A tile rank is gone (its process ended, or it was silent past --timeout on a wall that survives
// a lost rank): the others cancel their sends to it, and a rank on its host ends it if it is
// still there (stopped), so that mpirun does not wait for it at the end.
struct LostMsg {
    static constexpr Tag kTag = Tag::lost;
    static constexpr std::uint8_t kVersion = 1;
    std::int32_t rank = 0;
};

using Message = std::variant<TileHelloMsg, ViewMsg, ProgressMsg, SnapshotMsg, ImageMsg, QuitMsg,
                             TileResultMsg, ReleaseMsg, StartMsg, AliveMsg, PreviewMsg, JobMsg,
                             JobDoneMsg, RegionMsg, LandedMsg, StoreAskMsg, StoreMetaMsg,
                             StorePartMsg, CurveAskMsg, CurveMsg, FailedMsg, LostMsg>;

std::vector<std::byte> encode(const TileHelloMsg& m);
std::vector<std::byte> encode(const ViewMsg& m);
std::vector<std::byte> encode(const ProgressMsg& m);
std::vector<std::byte> encode(const SnapshotMsg& m);
std::vector<std::byte> encode(const ImageMsg& m);
std::vector<std::byte> encode(const QuitMsg& m);
std::vector<std::byte> encode(const TileResultMsg& m);
std::vector<std::byte> encode(const ReleaseMsg& m);
std::vector<std::byte> encode(const StartMsg& m);
std::vector<std::byte> encode(const AliveMsg& m);
std::vector<std::byte> encode(const PreviewMsg& m);
std::vector<std::byte> encode(const JobMsg& m);
std::vector<std::byte> encode(const JobDoneMsg& m);
std::vector<std::byte> encode(const RegionMsg& m);
std::vector<std::byte> encode(const LandedMsg& m);
std::vector<std::byte> encode(const StoreAskMsg& m);
std::vector<std::byte> encode(const StoreMetaMsg& m);
std::vector<std::byte> encode(const StorePartMsg& m);
std::vector<std::byte> encode(const CurveAskMsg& m);
std::vector<std::byte> encode(const CurveMsg& m);
std::vector<std::byte> encode(const FailedMsg& m);
std::vector<std::byte> encode(const LostMsg& m);
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

// Encodes `message` and sends it under its own tag.
template <class T>
void send_message(Comm& comm, int dest, const T& message) {
    comm.send(dest, T::kTag, encode(message));
}

}  // namespace isowall
