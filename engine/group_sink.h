#pragma once
// Where a frame's groups go. The engine hands every new group to a sink as soon as it is made:
// the renderer sink draws it into the frame being built, the recording sink keeps it for the
// correctness replay, and later a network sink will stream it to a remote client. A frame may
// feed several sinks at once through TeeSink.
#include <cstdint>
#include <span>
#include <vector>

#include "common/core/image.h"
#include "common/core/view.h"
#include "common/extract/surface_extractor.h"
#include "render/renderer.h"

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
    // The same without waiting for the renderer: the caller goes on casting while the groups are
    // drawn, and presented() tells when they show. False when this sink cannot; the caller then
    // calls present().
    virtual bool present_async() { return false; }
    // Whether every group added before the last present_async() shows (true when none is
    // outstanding); with `wait`, waits until they do and returns true.
    virtual bool presented(bool /*wait*/) { return true; }
    // Sizes `covered` to `rect` and writes covered[y * rect.width + x] != 0 when pixel
    // (rect.x + x, rect.y + y) shows the surface now; false when this sink cannot tell (the
    // readback ray orders then see nothing covered).
    virtual bool coverage(std::vector<std::uint8_t>& /*covered*/, const PixelRect& /*rect*/) {
        return false;
    }
    // Whether coverage() can tell: the engine keeps no frontier of full passes for a sink that
    // cannot (EngineOptions::frontier_seeds).
    virtual bool tells_coverage() const { return false; }
    // Whether seen() is wanted: the engine then looks up the group of every visited cell a ray
    // meets (a hash lookup per such ray), else it does not.
    virtual bool wants_seen() const { return false; }
    // A ray met a cell that group `group_id` took earlier in this frame, or before it when the
    // frame went on from cached groups (EngineOptions::begin_extractor_frame).
    virtual void seen(std::uint32_t /*group_id*/) {}
    // Whether seen() may come at the end of the level that met the cells, on the calling thread,
    // instead of at each ray: the engine then casts the level on several threads as it would
    // without seen(). False: seen() at each ray, and a level that wants it on one thread.
    virtual bool seen_after_level() const { return false; }
};

// Draws every group into a renderer's frame, which begin() resizes and clears.
class RendererSink final : public GroupSink {
  public:
    explicit RendererSink(Renderer& renderer) : renderer_(renderer) {}
    void begin(const FrameView& view) override;
    void add(const Group& group) override;
    double present() override;
    bool present_async() override;
    bool presented(bool wait) override;
    bool coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) override;
    bool tells_coverage() const override { return true; }
    // The frame as drawn so far (finishes pending draws first).
    void read_back(Image& out);
    void read_back(Image& out, const PixelRect& rect);

  private:
    Renderer& renderer_;
    glm::mat4 view_m_{1.0f}, proj_m_{1.0f};
};

// Keeps every group, in order: the replay that measures correctness redraws them.
class RecordingSink final : public GroupSink {
  public:
    void begin(const FrameView&) override { groups.clear(); }
    void add(const Group& group) override { groups.push_back(group); }
    std::vector<Group> groups;
};

// Forwards to each sink in turn; coverage comes from the first that can tell. An asynchronous
// present presents each sink that cannot present asynchronously at once, and is presented when
// every sink's is.
class TeeSink final : public GroupSink {
  public:
    explicit TeeSink(std::vector<GroupSink*> sinks) : sinks_(std::move(sinks)) {}
    void begin(const FrameView& view) override;
    void add(const Group& group) override;
    double present() override;
    bool present_async() override;
    bool presented(bool wait) override;
    bool coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) override;
    bool tells_coverage() const override;

  private:
    std::vector<GroupSink*> sinks_;
};

}  // namespace isowall
