#pragma once
// Drawing is one kind of sink (extract/group_sink.h): every group of a frame drawn into a
// renderer's frame, which begin() resizes and clears, and what the frame's pixels show read
// back for the engine's read-back ray orders and frontier seeds.
#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/image.h"
#include "extract/group_sink.h"
#include "render/renderer.h"

namespace isowall {

class RendererSink final : public GroupSink, public ShownPixels {
  public:
    explicit RendererSink(Renderer& renderer) : renderer_(renderer) {}
    void begin(const FrameView& view) override;
    void add(const Group& group) override;
    double present() override;
    bool present_async() override;
    bool presented(bool wait) override;
    void coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) override;
    // The frame as drawn so far (finishes pending draws first).
    void read_back(Image& out);
    void read_back(Image& out, const PixelRect& rect);

  private:
    Renderer& renderer_;
    glm::mat4 view_m_{1.0f}, proj_m_{1.0f};
};

}  // namespace isowall
