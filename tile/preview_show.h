#pragma once
// `isowall wall --control`: each tile sends the master a scaled-down copy of what it shows, as it
// builds, for the control window's live mosaic: at most kPreviewHz a second, and the last change
// of a frame always (tile/frame_show.h). The master keeps the latest of the current view.
#include "comm/comm.h"
#include "tile/frame_show.h"

namespace isowall {

inline constexpr double kPreviewHz = 10;

class PreviewShow final : public FrameShow {
  public:
    // max_side: the larger side of the tile in the control window (preview_max_side).
    PreviewShow(Comm& comm, int max_side) : comm_(comm), max_side_(max_side) {}
    double interval_s() const override { return 1.0 / kPreviewHz; }
    void show(const Image& tile, std::uint64_t generation) override;

  private:
    Comm& comm_;
    int max_side_;
};

}  // namespace isowall
