#include "app/step_volumes.h"

#include <string>

#include "core/error.h"

namespace isowall {

struct StepVolumes::Step {
    std::uint32_t step = 0;
    OpenedVolume volume;
    std::unique_ptr<SurfaceExtractor> extractor;
};

StepVolumes::StepVolumes(TimeSeries series, VolumeOptions options, VolumeUse use,
                         OpenExtractor open_extractor, const OpenedVolume& first,
                         SurfaceExtractor& first_extractor)
    : series_(std::move(series)),
      options_(std::move(options)),
      use_(use),
      open_extractor_(std::move(open_extractor)),
      dims_(first.volume.dims()),
      first_(first_extractor) {}

StepVolumes::~StepVolumes() = default;

SurfaceExtractor& StepVolumes::extractor(std::uint32_t step) {
    if (step == 0) return first_;
    if (step >= series_.steps.size())
        throw InputError(series_.pattern, "--volume",
                         "time step " + std::to_string(step) + ": the series has " +
                             std::to_string(series_.steps.size()) + " steps");
    for (auto it = kept_.begin(); it != kept_.end(); ++it)
        if ((*it)->step == step) {
            kept_.splice(kept_.begin(), kept_, it);
            return *kept_.front()->extractor;
        }
    auto s = std::make_unique<Step>();
    s->step = step;
    VolumeOptions o = options_;
    o.path = series_.steps[step].string();
    s->volume = open_volume(o, /*quiet=*/true, use_);
    const glm::ivec3 d = s->volume.volume.dims();
    if (d != dims_)
        throw InputError(o.path, "--volume",
                         "time step " + std::to_string(step) + " has " + std::to_string(d.x) + "x" +
                             std::to_string(d.y) + "x" + std::to_string(d.z) +
                             " voxels, step 0 has " + std::to_string(dims_.x) + "x" +
                             std::to_string(dims_.y) + "x" + std::to_string(dims_.z));
    s->extractor = open_extractor_(s->volume);
    ++opened_;
    kept_.push_front(std::move(s));
    // The one in use is the front: the oldest beyond kKept others go.
    while (kept_.size() > kKept + 1) kept_.pop_back();
    return *kept_.front()->extractor;
}

}  // namespace isowall
