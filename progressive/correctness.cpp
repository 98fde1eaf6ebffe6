#include "progressive/correctness.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/pixel_rect_ops.h"

namespace isowall {
namespace {

std::string size_text(const Image& image) {
    return std::to_string(image.width) + "x" + std::to_string(image.height);
}

// A frame whose buffers disagree with its size would be read out of bounds below.
void check_buffers(const Image& image, const char* name) {
    if (image.width < 0 || image.height < 0 || image.rgba.size() != image.pixel_count() * 4 ||
        image.depth.size() != image.pixel_count())
        throw std::invalid_argument(std::string("measure_correctness: ") + name + " image " +
                                    size_text(image) + " has " + std::to_string(image.rgba.size()) +
                                    " colour bytes and " + std::to_string(image.depth.size()) +
                                    " depth values");
}

// A significant pixel's error, e(P)^2 in units of 1 / (3 * 255^2), and whether each of R, G, B
// is within the tolerance (final_pixels' test).
struct PixelScore {
    std::uint32_t units = 0;
    bool within = false;
};
constexpr std::uint32_t kUndrawnUnits = 3 * 255 * 255;  // e(P) = 1: not drawn yet

PixelScore score_pixel(const Image& intermediate, const Image& final_image, std::size_t p,
                       bool drawn, int tolerance) {
    if (!drawn) return {kUndrawnUnits, false};
    PixelScore s{0, true};
    for (std::size_t k = 0; k < 3; ++k) {
        const int d = int(final_image.rgba[p * 4 + k]) - int(intermediate.rgba[p * 4 + k]);
        s.within = s.within && std::abs(d) <= tolerance;
        s.units += static_cast<std::uint32_t>(d * d);
    }
    return s;
}

Correctness from_sums(std::size_t significant, std::size_t matching, std::uint64_t units) {
    Correctness result;
    result.significant = significant;
    if (significant == 0) {
        result.final_pixels = 1;
        result.c = 1;
        return result;
    }
    const double n = double(significant);
    result.final_pixels = double(matching) / n;
    result.c = 1.0 - std::sqrt(double(units) / kUndrawnUnits / n);
    return result;
}

}  // namespace

Correctness measure_correctness(const Image& intermediate, const Image& final_image, int tolerance,
                                std::span<const std::uint8_t> drawn_before) {
    if (intermediate.width != final_image.width || intermediate.height != final_image.height)
        throw std::invalid_argument("measure_correctness: intermediate image is " +
                                    size_text(intermediate) + " but final image is " +
                                    size_text(final_image));
    check_buffers(intermediate, "intermediate");
    check_buffers(final_image, "final");
    if (!drawn_before.empty() && drawn_before.size() != final_image.pixel_count())
        throw std::invalid_argument("measure_correctness: drawn_before has " +
                                    std::to_string(drawn_before.size()) + " entries for " +
                                    size_text(final_image) + " pixels");

    std::size_t significant = 0, matching = 0;
    std::uint64_t units = 0;
    for (std::size_t p = 0; p < final_image.pixel_count(); ++p) {
        if (!(final_image.depth[p] < 1.0f)) continue;
        ++significant;
        const bool drawn =
            intermediate.depth[p] < 1.0f || (!drawn_before.empty() && drawn_before[p]);
        const PixelScore s = score_pixel(intermediate, final_image, p, drawn, tolerance);
        matching += s.within;
        units += s.units;
    }
    return from_sums(significant, matching, units);
}

CorrectnessTracker::CorrectnessTracker(Image final_image, int tolerance)
    : final_(std::move(final_image)), tolerance_(tolerance) {
    check_buffers(final_, "final");
    units_.assign(final_.pixel_count(), 0);
    matching_pixel_.assign(final_.pixel_count(), 0);
    for (std::size_t p = 0; p < final_.pixel_count(); ++p) {
        if (!(final_.depth[p] < 1.0f)) continue;
        ++significant_;
        units_[p] = kUndrawnUnits;
        units_sum_ += kUndrawnUnits;
    }
}

void CorrectnessTracker::update(const Image& shown, const PixelRect& rect) {
    if (shown.width != final_.width || shown.height != final_.height)
        throw std::invalid_argument("CorrectnessTracker: the frame is " + size_text(shown) +
                                    " but the final image is " + size_text(final_));
    check_buffers(shown, "intermediate");
    const PixelRect r = intersect(rect, {0, 0, final_.width, final_.height});
    for (int y = r.y; y < r.y + r.height; ++y)
        for (int x = r.x; x < r.x + r.width; ++x) {
            const std::size_t p = std::size_t(y) * std::size_t(final_.width) + std::size_t(x);
            if (!(final_.depth[p] < 1.0f)) continue;
            const PixelScore s = score_pixel(shown, final_, p, shown.depth[p] < 1.0f, tolerance_);
            units_sum_ = units_sum_ - units_[p] + s.units;
            matching_ = matching_ - matching_pixel_[p] + s.within;
            units_[p] = s.units;
            matching_pixel_[p] = s.within;
        }
}

Correctness CorrectnessTracker::now() const {
    return from_sums(significant_, matching_, units_sum_);
}

double CorrectnessTracker::error_squared_sum() const {
    return double(units_sum_) / kUndrawnUnits;
}

double coverage_iou(const Image& a, const Image& b) {
    if (a.width != b.width || a.height != b.height)
        throw std::invalid_argument("coverage_iou: images of " + size_text(a) + " and " +
                                    size_text(b));
    check_buffers(a, "first");
    check_buffers(b, "second");
    std::size_t both = 0, either = 0;
    for (std::size_t p = 0; p < a.pixel_count(); ++p) {
        const bool ca = a.depth[p] < 1.0f, cb = b.depth[p] < 1.0f;
        both += ca && cb;
        either += ca || cb;
    }
    return either == 0 ? 1.0 : double(both) / double(either);
}

Image box_filtered_truth(const Image& supersampled, int k) {
    if (k < 1 || supersampled.width % k != 0 || supersampled.height % k != 0)
        throw std::invalid_argument("box_filtered_truth: " + size_text(supersampled) +
                                    " is not a whole number of " + std::to_string(k) + "x" +
                                    std::to_string(k) + " boxes");
    check_buffers(supersampled, "supersampled");
    Image out;
    out.resize(supersampled.width / k, supersampled.height / k);
    const auto samples = static_cast<std::uint32_t>(k * k);
    for (int oy = 0; oy < out.height; ++oy)
        for (int ox = 0; ox < out.width; ++ox) {
            std::uint32_t sum[4] = {0, 0, 0, 0}, hits = 0;
            float nearest = 1.0f;
            for (int y = oy * k; y < oy * k + k; ++y)
                for (int x = ox * k; x < ox * k + k; ++x) {
                    const std::size_t s = static_cast<std::size_t>(y) * supersampled.width + x;
                    for (int c = 0; c < 4; ++c) sum[c] += supersampled.rgba[4 * s + c];
                    const float d = supersampled.depth[s];
                    hits += d < 1.0f;
                    nearest = std::min(nearest, d);
                }
            const std::size_t o = static_cast<std::size_t>(oy) * out.width + ox;
            for (int c = 0; c < 4; ++c)
                out.rgba[4 * o + c] = static_cast<std::uint8_t>((sum[c] + samples / 2) / samples);
            if (2 * hits >= samples) out.depth[o] = nearest;
        }
    return out;
}

Fidelity measure_fidelity(const Image& image, const Image& truth) {
    Fidelity f;
    f.c = measure_correctness(image, truth).c;
    f.iou = coverage_iou(image, truth);
    std::size_t covered = 0, off = 0;
    for (std::size_t p = 0; p < truth.pixel_count(); ++p) {
        if (truth.depth[p] >= 1.0f) continue;
        ++covered;
        bool far = image.depth[p] >= 1.0f;
        for (int c = 0; c < 3 && !far; ++c)
            far = std::abs(int(image.rgba[4 * p + c]) - int(truth.rgba[4 * p + c])) > 8;
        off += far;
    }
    f.off_share = covered == 0 ? 0.0 : double(off) / double(covered);
    return f;
}

bool passes_fidelity_gate(const Fidelity& image, const Fidelity& full) {
    return image.c >= full.c - kFidelityC && image.iou >= full.iou - kFidelityIoU;
}

void mark_drawn(const Image& frame, std::vector<std::uint8_t>& drawn) {
    check_buffers(frame, "drawn");
    drawn.resize(frame.pixel_count(), 0);
    for (std::size_t p = 0; p < frame.pixel_count(); ++p)
        if (frame.depth[p] < 1.0f) drawn[p] = 1;
}

}  // namespace isowall
