#pragma once
// How close an intermediate frame is to the final one, in the two measures of the dissertation:
// "final pixels" (chapters 2-3) and the correctness C = 1 - E (section 4.2).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/camera.h"
#include "core/image.h"

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
// A pixel of the intermediate frame counts as drawn where its depth is below 1, or where
// `drawn_before` (empty, or one entry per pixel) is non-zero: drawn before the depth buffer was
// cleared, as a client does when it goes to a finer level of detail. Its colour is still on
// screen, so a screen capture (the text's measure) sees it as drawn.
// Throws std::invalid_argument when the images differ in size or are malformed, or when
// drawn_before is neither empty nor one entry per pixel.
Correctness measure_correctness(const Image& intermediate, const Image& final_image,
                                int tolerance = 1, std::span<const std::uint8_t> drawn_before = {});

// measure_correctness kept up to date as an intermediate frame changes a rectangle at a time: each
// update costs the rectangle's pixels, not the frame's (a tile's curve measures the frame after
// every job and every landed result: hundreds of whole-frame measures, about a second of CPU a
// frame on a 1024x768 tile, which delayed the next frame of the measured wall). Sums are kept in
// integers, so an update undoes the pixels' old share exactly.
class CorrectnessTracker {
  public:
    // Against `final_image`, with nothing drawn yet; throws std::invalid_argument as
    // measure_correctness does for a malformed image.
    explicit CorrectnessTracker(Image final_image, int tolerance = 1);
    // The pixels of `rect` (clipped to the frame) now show those of `shown`, a frame of the final
    // image's size (std::invalid_argument otherwise).
    void update(const Image& shown, const PixelRect& rect);
    // What measure_correctness gives for the frame as updated so far.
    Correctness now() const;
    // The sum over significant pixels of e(P)^2 (C = 1 - sqrt(sum / significant)).
    double error_squared_sum() const;

  private:
    Image final_;
    int tolerance_;
    std::size_t significant_ = 0, matching_ = 0;
    std::uint64_t units_sum_ = 0;       // e(P)^2 in units of 1 / (3 * 255^2)
    std::vector<std::uint32_t> units_;  // each pixel's share of units_sum_
    std::vector<std::uint8_t> matching_pixel_;
};

// Pixels covered (depth below 1) in both images over pixels covered in either: 1 when neither
// covers any. Throws std::invalid_argument as measure_correctness does.
double coverage_iou(const Image& a, const Image& b);

// What a pixel can show: the truth a final image is judged against. `supersampled` is the full
// surface drawn at k x k samples per pixel (k times the screen's width and height, the same
// camera); each pixel of the result is the mean colour of its k x k samples, background (black)
// included, and is covered (depth: the nearest sample's) where at least half of its samples hit
// the surface, else depth 1. A point-sampled picture of a surface whose normals turn within a
// pixel is aliased; this one is not, so a coarser mesh whose shading stands for the fine one can
// be as close to it as the full mesh drawn at one sample per pixel. Throws std::invalid_argument
// when k < 1 or the image's sides are not multiples of k.
Image box_filtered_truth(const Image& supersampled, int k);
// The samples a side of a pixel of the truth the benchmarks and `render --against-truth` use.
inline constexpr int kTruthSamples = 4;

// A final image against the truth, beside the full surface drawn at one sample per pixel.
struct Fidelity {
    double c = 0;          // C = 1 - E against the truth (C_T)
    double iou = 0;        // coverage IoU against the truth
    double off_share = 0;  // of the truth's covered pixels, the share off by more than 8/255
};
Fidelity measure_fidelity(const Image& image, const Image& truth);

// The fidelity gate: an image passes where it is at least as close to the truth as the full
// surface at one sample per pixel, within kFidelityC in C_T and kFidelityIoU in coverage IoU.
inline constexpr double kFidelityC = 0.005;
inline constexpr double kFidelityIoU = 0.002;
bool passes_fidelity_gate(const Fidelity& image, const Fidelity& full);

// Marks in `drawn` (resized to one entry per pixel) every pixel of `frame` whose depth is below
// 1; entries already set stay set.
void mark_drawn(const Image& frame, std::vector<std::uint8_t>& drawn);

}  // namespace isowall
