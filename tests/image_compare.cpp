#include "tests/image_compare.h"

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <stdexcept>
#include <vector>

#include "files/image_io.h"

namespace isowall::test {
namespace {

std::string size_of(const Image& image) {
    return std::to_string(image.width) + "x" + std::to_string(image.height);
}

void require_pixels(const Image& image, const char* which) {
    const bool rgba_ok = image.rgba.size() == image.pixel_count() * 4;
    const bool depth_ok = image.depth.empty() || image.depth.size() == image.pixel_count();
    if (!rgba_ok || !depth_ok)
        throw std::invalid_argument(std::string("compare_images: image ") + which + " is " +
                                    size_of(image) + " with " + std::to_string(image.rgba.size()) +
                                    " colour and " + std::to_string(image.depth.size()) +
                                    " depth values");
}

// One flag per pixel: covered or not, by the rule `options.coverage` picks for this image.
std::vector<bool> coverage_mask(const Image& image, const CompareOptions& options) {
    const bool has_depth =
        std::any_of(image.depth.begin(), image.depth.end(), [](float d) { return d < 1.0f; });
    const bool by_depth = options.coverage == Coverage::depth ||
                          (options.coverage == Coverage::automatic && has_depth);
    std::vector<bool> mask(image.pixel_count());
    for (std::size_t i = 0; i < mask.size(); ++i) {
        if (by_depth) {
            mask[i] = !image.depth.empty() && image.depth[i] < 1.0f;
        } else {
            bool background = true;
            for (int k = 0; k < 3; ++k)
                background = background && image.rgba[4 * i + k] == options.background[k];
            mask[i] = !background;
        }
    }
    return mask;
}

int channel_error(const Image& a, const Image& b, std::size_t pixel) {
    int worst = 0;
    for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(int(a.rgba[4 * pixel + k]) - int(b.rgba[4 * pixel + k])));
    return worst;
}

}  // namespace

std::ostream& operator<<(std::ostream& os, const ImageComparison& c) {
    return os << "mask IoU " << c.mask_iou << " (" << c.covered_both << " of " << c.covered_either
              << " covered pixels), " << c.differing_pixels << " of " << c.pixels
              << " pixels differ (" << 100.0 * c.differing_share() << "%), channel error max "
              << c.max_channel_error << " mean " << c.mean_channel_error;
}

ImageComparison compare_images(const Image& a, const Image& b, const CompareOptions& options) {
    if (a.width != b.width || a.height != b.height)
        throw std::invalid_argument("compare_images: sizes differ: " + size_of(a) + " and " +
                                    size_of(b));
    require_pixels(a, "a");
    require_pixels(b, "b");
    const std::vector<bool> ca = coverage_mask(a, options), cb = coverage_mask(b, options);
    ImageComparison c;
    c.pixels = a.pixel_count();
    std::uint64_t error_sum = 0;
    for (std::size_t i = 0; i < c.pixels; ++i) {
        c.covered_both += ca[i] && cb[i];
        c.covered_either += ca[i] || cb[i];
        for (int k = 0; k < 3; ++k) {
            const int e = std::abs(int(a.rgba[4 * i + k]) - int(b.rgba[4 * i + k]));
            error_sum += std::uint64_t(e);
            c.max_channel_error = std::max(c.max_channel_error, e);
        }
        c.differing_pixels += channel_error(a, b, i) > options.channel_tolerance;
    }
    if (c.covered_either > 0) c.mask_iou = double(c.covered_both) / double(c.covered_either);
    if (c.pixels > 0) {
        c.equal_share = double(c.pixels - c.differing_pixels) / double(c.pixels);
        c.mean_channel_error = double(error_sum) / (3.0 * double(c.pixels));
    }
    return c;
}

void write_diff_images(const std::filesystem::path& dir, const std::string& name,
                       const Image& rendered, const Image& baseline,
                       const CompareOptions& options) {
    std::filesystem::create_directories(dir);
    const auto rendered_path = dir / (name + "_rendered.png");
    const auto baseline_path = dir / (name + "_baseline.png");
    const auto diff_path = dir / (name + "_diff.png");
    write_image(rendered_path, rendered);
    std::cout << "rendered: " << rendered_path.string() << "\n";
    if (baseline.pixel_count() > 0) {
        write_image(baseline_path, baseline);
        std::cout << "baseline: " << baseline_path.string() << "\n";
    }
    if (baseline.pixel_count() == 0) return;
    if (rendered.width != baseline.width || rendered.height != baseline.height) {
        std::cout << "no diff image: rendered is " << size_of(rendered) << ", baseline "
                  << size_of(baseline) << "\n";
        return;
    }
    const std::vector<bool> cr = coverage_mask(rendered, options);
    const std::vector<bool> cb = coverage_mask(baseline, options);
    Image diff;
    diff.resize(rendered.width, rendered.height);
    for (std::size_t i = 0; i < diff.pixel_count(); ++i) {
        std::array<std::uint8_t, 3> colour{0, 0, 0};
        if (cr[i] && !cb[i])
            colour = {255, 0, 0};
        else if (cb[i] && !cr[i])
            colour = {0, 255, 0};
        else if (channel_error(rendered, baseline, i) > options.channel_tolerance)
            colour = {255, 255, 255};
        else if (cr[i])
            colour = {64, 64, 64};
        std::copy(colour.begin(), colour.end(), diff.rgba.begin() + std::ptrdiff_t(4 * i));
        diff.rgba[4 * i + 3] = 255;
    }
    write_image(diff_path, diff);
    std::cout << "diff:     " << diff_path.string()
              << " (red: only rendered covered, green: only baseline, white: colour differs)\n";
}

}  // namespace isowall::test
