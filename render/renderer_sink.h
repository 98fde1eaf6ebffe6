#pragma once
// Drawing is one kind of sink (extract/group_sink.h): every group of a frame drawn into a
// renderer's frame, which begin() resizes and clears, and what the frame's pixels show read
// back for the engine's read-back ray orders and frontier seeds. A group's triangles that cover no
// pixel centre of the frame are left out before drawing (core/sample_cull.h): the frame is the
// same, and the rasteriser's work follows the pixels rather than the triangles.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/image.h"
#include "core/sample_cull.h"
#include "extract/group_sink.h"
#include "render/renderer.h"

namespace isowall {

class RendererSink final : public GroupSink, public ShownPixels {
  public:
    // every_triangle: draw each group whole (for studies of what the cull saves).
    explicit RendererSink(Renderer& renderer, bool every_triangle = false)
        : renderer_(renderer), every_triangle_(every_triangle) {}
    void begin(const FrameView& view) override;
    void add(const Group& group) override;
    double present() override;
    bool present_async() override;
    bool presented(bool wait) override;
    void coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) override;
    // The frame as drawn so far (finishes pending draws first).
    void read_back(Image& out);
    void read_back(Image& out, const PixelRect& rect);
    // Triangles given to add() since begin(), and those of them drawn.
    std::size_t given_triangles() const { return given_; }
    std::size_t drawn_triangles() const { return drawn_; }

  private:
    Renderer& renderer_;
    bool every_triangle_;
    glm::mat4 view_m_{1.0f}, proj_m_{1.0f};
    int width_ = 0, height_ = 0;
    std::size_t given_ = 0, drawn_ = 0;
    Mesh sampled_;               // the group's triangles that cover a pixel centre
    SampleCullScratch scratch_;  // the cull's, kept between groups
};

}  // namespace isowall
