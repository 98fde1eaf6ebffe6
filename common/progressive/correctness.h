#pragma once
// How close an intermediate frame is to the final one, in the two measures of the dissertation:
// "final pixels" (chapters 2-3) and the correctness C = 1 - E (section 4.2).
#include <cstddef>

#include "common/core/image.h"

namespace isowall {

struct Correctness {
    // Share of significant pixels that are drawn in the intermediate frame with the final
    // colour (each of R, G, B within the tolerance), in [0,1].
    double final_pixels = 0;
    // 1 - E, where E is the RMS over significant pixels of e(P): 1 for a pixel not drawn yet,
    // else the RMS of the RGB differences normalised to [0,1]. In [0,1].
    double c = 0;
    // Pixels covered (depth < 1) in the final image. Only these count: the rest is background
    // and carries no information, even where the intermediate frame drew something.
    std::size_t significant = 0;
};

// Both measures are 1 when the final image has no significant pixel (nothing to match).
// tolerance is in 8-bit units per channel and only affects final_pixels; C is exact.
// Throws std::invalid_argument when the two images differ in size or are malformed.
Correctness measure_correctness(const Image& intermediate, const Image& final_image,
                                int tolerance = 1);

}  // namespace isowall
