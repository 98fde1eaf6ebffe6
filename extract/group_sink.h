#pragma once
// Where a frame's groups go. The engine hands every new group to a sink as soon as it is made:
// a renderer's sink (render/renderer_sink.h) draws it into the frame being built, a recording
// sink keeps it for the correctness replay, a server's sink streams it to a client; TeeSink feeds
// several at once. Two other parties may watch a frame, each optional and each its own
// interface, so that the sink itself carries no switches (FrameOutput gathers the three):
//   - ShownPixels tells what the frame's pixels show now: the read-back ray orders and the
//     frontier seeds read it. Without it they see nothing covered and no frontier is kept.
//   - SeenGroups is told of each earlier group whose cells a ray meets: a wall helper draws
//     those into its help image, a server names the cached groups a client should show.
#include <cstdint>
#include <type_traits>
#include <vector>

#include "core/camera.h"
#include "core/view.h"
#include "extract/group.h"

namespace isowall {

class GroupSink {
  public:
    virtual ~GroupSink() = default;
    // A new frame of `view` (the whole screen); nothing of an earlier frame shows any more.
    virtual void begin(const FrameView& /*view*/) {}
    virtual void add(const Group& group) = 0;
    // Makes every group added so far visible, as a display does at its next refresh. Called at
    // most once per refresh and at the end of each ray-order level; returns the seconds it took.
    virtual double present() { return 0; }
    // The same without waiting: the caller goes on casting while the groups are drawn, and
    // presented() tells when they show. False when nothing was started (a sink that has nothing
    // to wait for); the caller then calls present().
    virtual bool present_async() { return false; }
    // Whether every group added before the last present_async() shows (true when none is
    // outstanding); with `wait`, waits until they do and returns true.
    virtual bool presented(bool /*wait*/) { return true; }
};

class ShownPixels {
  public:
    virtual ~ShownPixels() = default;
    // Sizes `covered` to `rect` and writes covered[y * rect.width + x] != 0 when pixel
    // (rect.x + x, rect.y + y) shows the surface now.
    virtual void coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) = 0;
};

class SeenGroups {
  public:
    virtual ~SeenGroups() = default;
    // A ray met a cell that group `group_id` took earlier in this frame, or before it when the
    // frame went on from cached groups (EngineOptions::begin_extractor_frame). On one thread
    // (EngineOptions::threads = 1) this comes at the ray; on several, at the end of the
    // ray-order level that met the cells, on the calling thread, before its coverage is read.
    virtual void seen(std::uint32_t group_id) = 0;
};

// What a frame is cast into. Made from a sink alone, it takes the sink as its ShownPixels and
// its SeenGroups where the sink's type is one (a RendererSink tells coverage); a caller whose
// watchers change from job to job names them.
struct FrameOutput {
    template <class Sink>
    requires std::is_base_of_v<GroupSink, Sink> FrameOutput(
        Sink& sink)  // NOLINT(google-explicit-constructor): a sink is an output
        : groups(sink) {
        if constexpr (std::is_base_of_v<ShownPixels, Sink>) shown = &sink;
        if constexpr (std::is_base_of_v<SeenGroups, Sink>) seen = &sink;
    }
    FrameOutput(GroupSink& sink, ShownPixels* shown_by, SeenGroups* seen_by)
        : groups(sink), shown(shown_by), seen(seen_by) {}

    GroupSink& groups;
    ShownPixels* shown = nullptr;
    SeenGroups* seen = nullptr;
};

// Keeps every group, in order: the replay that measures correctness redraws them.
class RecordingSink final : public GroupSink {
  public:
    void begin(const FrameView&) override { groups.clear(); }
    void add(const Group& group) override { groups.push_back(group); }
    std::vector<Group> groups;
};

// Forwards to each sink in turn. An asynchronous present presents each sink that cannot present
// asynchronously at once, and is presented when every sink's is.
class TeeSink final : public GroupSink {
  public:
    explicit TeeSink(std::vector<GroupSink*> sinks) : sinks_(std::move(sinks)) {}
    void begin(const FrameView& view) override;
    void add(const Group& group) override;
    double present() override;
    bool present_async() override;
    bool presented(bool wait) override;

  private:
    std::vector<GroupSink*> sinks_;
};

}  // namespace isowall
