#pragma once
// The drawing side of `isowall view`, apart from sockets: the messages of a request go in, the
// frame is drawn as they arrive, and a timeline of what the client had on screen is kept (bytes
// received, groups, triangles, and after the frame both correctness measures by a replay).
//
// What is drawn (the dissertation's section 4.1.4):
//   - groups are drawn as they arrive, each decoded once; with progressive LOD the depth buffer
//     is cleared when a finer level begins, so the finer surface covers the coarser one;
//   - a group coarser than what the frame already shows is not drawn (it could not be drawn over
//     the finer groups), nor one sent with draw_from_next_frame; both are cached when caching;
//   - VisibleMsg names cached groups to draw by slot: the client must hold each (a protocol error
//     if not) and draws them coarse levels first, as a finer group drawn first would keep the
//     coarser ones off the screen;
//   - at the end of a frame that drew any coarse group, the frame is drawn again from its
//     full-resolution groups alone, so the final image holds no coarse leftovers and equals the
//     image of the same view without LOD.
// The cache follows the server's stream, not the client's requests: the server's worker may skip
// requests, so only it knows what the client must hold. A group with a cache generation
// (GroupMsg::cache_gen, of any request, as late groups are cached too) is appended to the cache;
// one of another generation first drops the cache. Groups arrive in the order the server gave
// them slots, so a group's slot is its index. The cache is kept while requests do not cache: the
// server may have skipped such a request and still name the generation's slots.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/image.h"
#include "progressive/correctness.h"
#include "remote/view_protocol.h"
#include "render/renderer.h"

namespace isowall::remote {

struct ClientSample {
    double time_s = 0;            // since the request was sent
    std::uint64_t bytes = 0;      // received for this request, headers included
    std::uint64_t groups = 0;     // received (new groups) for this request
    std::uint64_t cells = 0;      // of them, in the cells encoding (the adaptive server's choice)
    std::uint64_t exact = 0;      // of them, made exact after a step by an ExactMsg
    std::uint64_t named = 0;      // cached groups named visible
    std::uint64_t triangles = 0;  // drawn
    std::size_t ops = 0;          // draw steps done by then (for the replay)
    int level = -1;               // the finest level of detail drawn by then; -1: none
    Correctness correctness;      // against the final image; filled by measure()
};

struct ClientFrameResult {
    bool completed = false;
    EndOfFrameMsg end;  // the server's figures
    std::vector<ClientSample> timeline;
    Image final_image;
};

class ClientFrames {
  public:
    explicit ClientFrames(Renderer& renderer) : renderer_(renderer) {}

    // A request was sent at `now_s`: a new frame of its view (the previous one is abandoned).
    void begin(const RequestMsg& request, double now_s);
    // A message from the server, `wire_bytes` long, that arrived at `now_s`. True when it ended
    // the current frame (then result() holds it). Messages of older requests only fill the cache.
    // Throws WireError for a group that does not decode or names an unknown cached group, and
    // RemoteError (below) for an ErrorMsg.
    bool handle(const RemoteMessage& m, std::size_t wire_bytes, double now_s);
    // The last frame ended; measure() first fills the correctness of its samples.
    const ClientFrameResult& result() const { return result_; }
    // The request of the current (or last) frame.
    const RequestMsg& request() const { return request_; }
    // Replays the frame's draw steps and measures each sample against the final image.
    void measure();
    // What is on screen now.
    void read_back(Image& out) { renderer_.read_back(out); }
    // What decoding groups cost since the last report, per encoding, once kReportEveryS has
    // passed since it (at `now_s`) and something was decoded; nullopt otherwise.
    std::optional<DecodeRateMsg> decode_report(double now_s);
    static constexpr double kReportEveryS = 0.05;

  private:
    struct Cached {
        std::shared_ptr<const Mesh> mesh;
        int level = 0;
    };
    struct Op {
        std::shared_ptr<const Mesh> mesh;  // null: clear the depth buffer
    };
    void draw(const std::shared_ptr<const Mesh>& mesh, int level);
    void sample(double now_s, bool force);
    void finish_frame(const EndOfFrameMsg& end, double now_s);
    void handle_group(const GroupMsg& g, std::size_t wire_bytes, double now_s);
    void handle_visible(const VisibleMsg& v, std::size_t wire_bytes, double now_s);
    void handle_exact(const ExactMsg& x, std::size_t wire_bytes, double now_s);

    Renderer& renderer_;
    RequestMsg request_;
    bool active_ = false;
    double start_s_ = 0, last_sample_s_ = -1;
    std::uint64_t last_sample_bytes_ = 0;
    ClientSample now_;
    int draw_level_ = 1 << 30;  // the finest level drawn in this frame so far
    bool drew_coarse_ = false;
    std::size_t redraw_op_ = SIZE_MAX;  // where the end-of-frame redraw began, if any
    std::vector<Op> ops_;
    std::vector<std::shared_ptr<const Mesh>> finals_;  // full-resolution groups of the frame
    // Groups of the frame whose gradients' voxels came to a step: their bytes, and where their
    // mesh is in finals_, until their ExactMsg comes (remote/cell_codec.h).
    struct Stepped {
        GroupKey key;
        std::vector<std::byte> encoded;
        std::size_t final_index = 0;
    };
    std::vector<Stepped> stepped_;
    bool replaced_ = false;        // an exact mesh took a stepped one's place: redraw at the end
    std::vector<Cached> cache_;    // index = slot in generation cache_gen_
    std::uint64_t cache_gen_ = 0;  // 0: none yet
    ClientFrameResult result_;
    // Decoded since the last report, by encoding id (DecodeRateMsg).
    std::array<DecodeRateMsg::Entry, kDecodeRateEncodings> decoded_{};
    double last_report_s_ = 0;
};

// The server's ErrorMsg, as an exception: the text names the server's complaint.
struct RemoteError : std::runtime_error {
    RemoteError(ErrorCode c, const std::string& text) : std::runtime_error(text), code(c) {}
    ErrorCode code;
};

}  // namespace isowall::remote
