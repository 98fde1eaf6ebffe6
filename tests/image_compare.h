#pragma once
// The one way tests compare two frames: how well their coverage masks overlap and how many pixels
// differ in colour, plus the evidence (rendered, baseline, diff images) when a comparison fails.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <ostream>
#include <string>

#include "core/image.h"

namespace isowall::test {

// Where a pixel counts as covered (something drawn into it).
enum class Coverage {
    // depth where the image has any (some depth < 1), else colour. An image read from a file has
    // depth 1 everywhere, like a rendered frame with nothing drawn; for either, colour says the
    // same as long as `background` is the renderer's clear colour (black) and no drawn pixel is
    // exactly that colour (the shader's ambient term keeps every lit pixel above it).
    automatic,
    depth,   // depth < 1
    colour,  // RGB is not `background`
};

struct CompareOptions {
    int channel_tolerance = 1;  // a pixel is equal when every RGB channel differs by at most this
    Coverage coverage = Coverage::automatic;
    std::array<std::uint8_t, 3> background{0, 0, 0};  // RGB of "nothing drawn", for colour coverage
};

struct ImageComparison {
    std::size_t pixels = 0;
    std::size_t covered_both = 0;    // covered in both images
    std::size_t covered_either = 0;  // covered in at least one
    // covered_both / covered_either; 1 when neither image covers anything (the masks agree).
    double mask_iou = 1;
    std::size_t differing_pixels = 0;  // some RGB channel differs by more than channel_tolerance
    double equal_share = 1;            // (pixels - differing_pixels) / pixels; 1 for no pixels
    int max_channel_error = 0;         // largest |a - b| over every RGB channel of every pixel
    double mean_channel_error = 0;     // mean |a - b| over every RGB channel of every pixel

    double differing_share() const { return 1.0 - equal_share; }
};

std::ostream& operator<<(std::ostream& os, const ImageComparison& c);

// Compares the RGB channels (alpha is ignored) and coverage of two images of one size. Throws
// std::invalid_argument naming both sizes when they differ, or when an image's rgba or (non-empty)
// depth does not hold one value per pixel.
ImageComparison compare_images(const Image& a, const Image& b, const CompareOptions& options = {});

// Writes NAME_rendered.png, NAME_baseline.png and NAME_diff.png into `dir` (created if needed) and
// prints their paths. The diff is red where only `rendered` is covered, green where only
// `baseline` is, white where both or neither are but a channel differs beyond the tolerance, dark
// grey where both are covered and agree, and black elsewhere: the shape stays readable while
// every disagreement stands out.
void write_diff_images(const std::filesystem::path& dir, const std::string& name,
                       const Image& rendered, const Image& baseline,
                       const CompareOptions& options = {});

}  // namespace isowall::test
