// Issue 34's adaptive server (remote/encoding_choice.h): which encoding the chooser picks for a
// fast link, a slow one, and a client that takes cells more slowly than the link could, and how
// rarely it explores the dearer one. Pure: the costs are fed in, as a session measures them.
#include <gtest/gtest.h>

#include <cstdio>

#include "remote/encoding_choice.h"

namespace isowall::remote {
namespace {

// One group of 2000 triangles: cells 1.2 B and 0.35 us a triangle to encode, compact+zstd 6.5 B
// and 0.13 us (the codec benchmark's figures on the shared head), made by the engine in 0.3 us a
// triangle. A send of n bytes blocks for n / rate seconds (rate 0: never blocks).
struct Link {
    double cells_rate = 0, compact_rate = 0;
};

// With `cells_decode_s` > 0 the client reports its decoding too: that many seconds a triangle for
// cells, 0.026 us for compact+zstd (39 M triangles/s, the codec benchmark on the head).
std::uint64_t run(EncodingChooser& c, const Link& link, int groups, double cells_decode_s = 0) {
    std::uint64_t cells = 0;
    for (int i = 0; i < groups; ++i) {
        const GroupEncoding e = c.next();
        const bool is_cells = e == GroupEncoding::cells;
        cells += is_cells ? 1 : 0;
        const std::size_t bytes = is_cells ? 2400 : 13000;
        c.encoded(e, 2000, bytes, 2000 * (is_cells ? 0.35e-6 : 0.13e-6), 2000 * 0.3e-6);
        const double rate = is_cells ? link.cells_rate : link.compact_rate;
        c.sent(e, bytes, rate > 0 ? double(bytes) / rate : 0);
        if (cells_decode_s > 0) c.decoded(e, 2000, 2000 * (is_cells ? cells_decode_s : 0.026e-6));
    }
    return cells;
}

TEST(EncodingChoice, AFastLinkGetsTheCheaperEncodingASlowOneTheSmaller) {
    EncodingChooser fast;
    const auto fast_cells = run(fast, {}, 400);
    EncodingChooser slow;
    const auto slow_cells = run(slow, {125e3, 125e3}, 400);  // 1 Mbit/s
    std::printf("cells chosen for 400 groups: %llu on a link that never blocks, %llu at 1 Mbit/s\n",
                (unsigned long long)fast_cells, (unsigned long long)slow_cells);
    EXPECT_LT(fast_cells, 400u / 8);
    EXPECT_GT(slow_cells, 400u - 400u / 8);
    EXPECT_GT(fast.cost_per_triangle(GroupEncoding::cells),
              fast.cost_per_triangle(GroupEncoding::compact_zstd));
    EXPECT_NEAR(slow.bytes_per_s(GroupEncoding::cells), 125e3, 1.0);
}

TEST(EncodingChoice, AClientSlowAtCellsIsSeenThroughItsSends) {
    // 100 Mbit/s, but the client takes cells' bytes at 3 MB/s (its marching cubes): compact wins.
    EncodingChooser c;
    const auto cells = run(c, {3e6, 12.5e6}, 400);
    EXPECT_LT(cells, 400u / 8);
    // The same client on a 10 Mbit/s link: the link is the bottleneck, cells win.
    EncodingChooser ten;
    EXPECT_GT(run(ten, {1.25e6, 1.25e6}, 400), 400u - 400u / 8);
}

TEST(EncodingChoice, AClientsDecodeReportCounts) {
    // 30 Mbit/s: compact+zstd's 6.5 B a triangle take 1.7 us on the link, cells' 1.2 B 0.3 us,
    // and the server makes and encodes cells in 0.65 us: cells win...
    EncodingChooser blind;
    EXPECT_GT(run(blind, {3.75e6, 3.75e6}, 400), 400u - 400u / 8);
    // ...unless the client decodes them at 0.5 M triangles/s (2 us), slower than compact's link.
    EncodingChooser told;
    EXPECT_LT(run(told, {3.75e6, 3.75e6}, 400, 2e-6), 400u / 8);
    EXPECT_NEAR(told.cost_per_triangle(GroupEncoding::cells), 2e-6, 1e-9);
    // The same client at 1 Mbit/s: the link is the bottleneck (cells 9.6 us, compact 52), cells.
    EncodingChooser slow;
    EXPECT_GT(run(slow, {125e3, 125e3}, 400, 2e-6), 400u - 400u / 8);
    // Reports of encodings the chooser does not pick between change nothing.
    EncodingChooser quiet;
    quiet.decoded(GroupEncoding::vertices, 2000, 1.0);
    EXPECT_EQ(quiet.cost_per_triangle(GroupEncoding::compact_zstd), 0);
}

TEST(EncodingChoice, ExploresTheOtherRarelyButAlways) {
    EncodingChooser c;
    const auto cells = run(c, {125e3, 125e3}, 1000);
    const std::uint64_t compact = 1000 - cells;
    // Compact is about 5x dearer at 1 Mbit/s: explored every 16 x 5 = 80 groups or so.
    std::printf("1000 groups at 1 Mbit/s: %llu sent as compact+zstd\n",
                (unsigned long long)compact);
    EXPECT_GE(compact, 5u);
    EXPECT_LE(compact, 1000u / 40);
    EXPECT_EQ(c.chosen(GroupEncoding::compact_zstd), compact);
}

TEST(EncodingChoice, ALinkThatSlowsDownIsFollowed) {
    EncodingChooser c;
    run(c, {}, 200);  // fast: compact
    const auto cells = run(c, {125e3, 125e3}, 400);
    std::printf("after the link fell to 1 Mbit/s: %llu of 400 groups as cells\n",
                (unsigned long long)cells);
    EXPECT_GT(cells, 300u);
}

// The link and the server overlap: at 100 Mbit/s compact+zstd's 6.5 bytes a triangle take
// 0.52 us, against the server's 0.3 + 0.35 us for cells and 0.3 + 0.13 for compact. Compact is then
// the sooner (0.52 against 0.65), though a sum of the two would charge it 0.95.
TEST(EncodingChoice, TheServerAndTheLinkOverlap) {
    EncodingChooser c;
    const auto cells = run(c, {12.5e6, 12.5e6}, 400);
    EXPECT_LT(cells, 400u / 8);
    EXPECT_NEAR(c.cost_per_triangle(GroupEncoding::compact_zstd), 0.52e-6, 0.01e-6);
    EXPECT_NEAR(c.cost_per_triangle(GroupEncoding::cells), 0.65e-6, 0.01e-6);
}

// Passes of a few triangles (a header each, and a while to find them) weigh by their triangles:
// they do not swamp what thousands of triangles showed.
TEST(EncodingChoice, TinyPassesWeighByTheirTriangles) {
    EncodingChooser c;
    run(c, {}, 100);
    for (int i = 0; i < 20; ++i) {
        const GroupEncoding e = c.next();
        c.encoded(e, 2, 200, 20e-6, 1e-3);  // 2 triangles: 100 B and 500 us a triangle to make
        c.sent(e, 200, 0);
    }
    EXPECT_LT(c.cost_per_triangle(GroupEncoding::compact_zstd), 10e-6);
    EXPECT_EQ(c.next(), GroupEncoding::compact_zstd);
}

}  // namespace
}  // namespace isowall::remote
