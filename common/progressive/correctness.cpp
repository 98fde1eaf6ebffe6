#include "common/progressive/correctness.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

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

    std::size_t significant = 0;
    std::size_t matching = 0;
    double error_squared_sum = 0;  // sum of e(P)^2
    for (std::size_t p = 0; p < final_image.pixel_count(); ++p) {
        if (!(final_image.depth[p] < 1.0f)) continue;
        ++significant;
        const bool drawn =
            intermediate.depth[p] < 1.0f || (!drawn_before.empty() && drawn_before[p]);
        if (!drawn) {
            error_squared_sum += 1.0;  // not drawn yet: no information, e(P) = 1
            continue;
        }
        bool within = true;
        double channel_squared_sum = 0;
        for (std::size_t k = 0; k < 3; ++k) {
            const int d = int(final_image.rgba[p * 4 + k]) - int(intermediate.rgba[p * 4 + k]);
            within = within && std::abs(d) <= tolerance;
            const double dn = d / 255.0;
            channel_squared_sum += dn * dn;
        }
        if (within) ++matching;
        // e(P)^2 = (dR^2 + dG^2 + dB^2) / 3; the square root cancels in the RMS.
        error_squared_sum += channel_squared_sum / 3.0;
    }

    Correctness result;
    result.significant = significant;
    if (significant == 0) {
        result.final_pixels = 1;
        result.c = 1;
        return result;
    }
    const double n = double(significant);
    result.final_pixels = double(matching) / n;
    result.c = 1.0 - std::sqrt(error_squared_sum / n);
    return result;
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

void mark_drawn(const Image& frame, std::vector<std::uint8_t>& drawn) {
    check_buffers(frame, "drawn");
    drawn.resize(frame.pixel_count(), 0);
    for (std::size_t p = 0; p < frame.pixel_count(); ++p)
        if (frame.depth[p] < 1.0f) drawn[p] = 1;
}

}  // namespace isowall
