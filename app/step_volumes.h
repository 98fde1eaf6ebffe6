#pragma once
// A tile rank's time steps (volume/time_steps.h): each step's volume opened, and its octree mapped
// from the cache or built, the first time a frame shows it; the last few kept open, so that
// stepping back and forth or playing a short series in a loop opens nothing again. Every step must
// have step 0's voxels.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <list>
#include <memory>

#include "cli/volume_options.h"
#include "extract/surface_extractor.h"
#include "volume/time_steps.h"

namespace isowall {

class StepVolumes {
  public:
    // Steps kept open beside the one in use.
    static constexpr std::size_t kKept = 3;

    // How the rank makes an opened volume's extractor (its octree mapped or built).
    using OpenExtractor = std::function<std::unique_ptr<SurfaceExtractor>(const OpenedVolume&)>;

    // `first` is step 0's volume and extractor, opened by the caller (kept for the rank's life);
    // `options` the --volume options every step is opened with (its path replaced).
    StepVolumes(TimeSeries series, VolumeOptions options, VolumeUse use,
                OpenExtractor open_extractor, const OpenedVolume& first,
                SurfaceExtractor& first_extractor);
    ~StepVolumes();

    // Step `step`'s extractor, valid until the next call that opens a step kKept + 1 calls later.
    // Throws an InputError naming the step's file for a step past the series or a volume whose
    // voxels differ from step 0's.
    SurfaceExtractor& extractor(std::uint32_t step);
    std::size_t opened() const { return opened_; }  // steps opened (step 0 aside), for tests

  private:
    struct Step;
    TimeSeries series_;
    VolumeOptions options_;
    VolumeUse use_;
    OpenExtractor open_extractor_;
    glm::ivec3 dims_;
    SurfaceExtractor& first_;
    std::list<std::unique_ptr<Step>> kept_;  // the most recently used first
    std::size_t opened_ = 0;
};

}  // namespace isowall
