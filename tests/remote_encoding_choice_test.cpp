// The adaptive server (remote/encoding_choice.h): which encoding the chooser picks for a
// fast link, a slow one, and a client that takes cells more slowly than the link could, and how
// rarely it explores the dearer one. Pure: the costs are fed in, as a session measures them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "remote/encoding_choice.h"

namespace isowall::remote {
namespace {

// One group of 2000 triangles: cells 1.2 B and 0.35 us a triangle to encode, compact+zstd 6.5 B
// and 0.13 us (the codec benchmark's figures on the shared head), made by the engine in 0.3 us a
// triangle. A send of n bytes blocks for n / rate seconds (rate 0: never blocks).

// One group of the costs above: the chooser's pick (`now_s`: its clock, negative for none),
// encoded; the engine made it in `making_s` a triangle.
struct Pick {
    GroupEncoding e;
    bool cells;
    std::size_t bytes;
};
Pick pick(EncodingChooser& c, double now_s = -1, double making_s = 0.3e-6) {
    const GroupEncoding e = c.next(now_s);
    const bool cells = e == GroupEncoding::cells;
    const std::size_t bytes = cells ? 2400 : 13000;
    c.encoded(e, 2000, bytes, 2000 * (cells ? 0.35e-6 : 0.13e-6), 2000 * making_s);
    return {e, cells, bytes};
}

// With `cells_decode_s` > 0 the client reports its decoding too: that many seconds a triangle for
// cells, 0.026 us for compact+zstd (39 M triangles/s, the codec benchmark on the head).
std::uint64_t run(EncodingChooser& c, double rate, int groups, double cells_decode_s = 0) {
    std::uint64_t cells = 0;
    for (int i = 0; i < groups; ++i) {
        const auto [e, is_cells, bytes] = pick(c);
        cells += is_cells ? 1 : 0;
        c.sent(e, bytes, rate > 0 ? double(bytes) / rate : 0);
        if (cells_decode_s > 0) c.decoded(e, 2000, 2000 * (is_cells ? cells_decode_s : 0.026e-6));
    }
    return cells;
}

TEST(EncodingChoice, AFastLinkGetsTheCheaperEncodingASlowOneTheSmaller) {
    EncodingChooser fast;
    const auto fast_cells = run(fast, 0, 400);
    EncodingChooser slow;
    const auto slow_cells = run(slow, 125e3, 400);  // 1 Mbit/s
    std::printf("cells chosen for 400 groups: %llu on a link that never blocks, %llu at 1 Mbit/s\n",
                (unsigned long long)fast_cells, (unsigned long long)slow_cells);
    EXPECT_LT(fast_cells, 400u / 8);
    EXPECT_GT(slow_cells, 400u - 400u / 8);
    EXPECT_GT(fast.cost_per_triangle(GroupEncoding::cells),
              fast.cost_per_triangle(GroupEncoding::compact_zstd));
    EXPECT_NEAR(slow.bytes_per_s(), 125e3, 1.0);
}

TEST(EncodingChoice, AClientsDecodeReportCounts) {
    // 30 Mbit/s: compact+zstd's 6.5 B a triangle take 1.7 us on the link, cells' 1.2 B 0.3 us,
    // and the server makes and encodes cells in 0.65 us: cells win...
    EncodingChooser blind;
    EXPECT_GT(run(blind, 3.75e6, 400), 400u - 400u / 8);
    // ...unless the client decodes them at 0.5 M triangles/s (2 us), slower than compact's link.
    EncodingChooser told;
    EXPECT_LT(run(told, 3.75e6, 400, 2e-6), 400u / 8);
    EXPECT_NEAR(told.cost_per_triangle(GroupEncoding::cells), 2e-6, 1e-9);
    // The same client at 1 Mbit/s: the link is the bottleneck (cells 9.6 us, compact 52), cells.
    EncodingChooser slow;
    EXPECT_GT(run(slow, 125e3, 400, 2e-6), 400u - 400u / 8);
    // Reports of encodings the chooser does not pick between change nothing.
    EncodingChooser quiet;
    quiet.decoded(GroupEncoding::vertices, 2000, 1.0);
    EXPECT_EQ(quiet.cost_per_triangle(GroupEncoding::compact_zstd), 0);
}

// As the session does: each group goes in the chooser's encoding, and while measuring it is
// encoded the other way too, after the send. Returns the number of the first group sent as
// compact+zstd (0: none).
std::uint64_t run_measuring_first(EncodingChooser& c, double rate, int groups,
                                  std::uint64_t& cells) {
    std::uint64_t first_compact = 0;
    cells = 0;
    const auto encoded = [&](GroupEncoding e) {
        const bool is_cells = e == GroupEncoding::cells;
        c.encoded(e, 2000, is_cells ? 2400 : 13000, 2000 * (is_cells ? 0.35e-6 : 0.13e-6),
                  2000 * 0.3e-6);
    };
    for (int i = 0; i < groups; ++i) {
        const GroupEncoding e = c.next();
        const bool other = c.wants_measure(other_encoding(e));
        encoded(e);
        const std::size_t bytes = e == GroupEncoding::cells ? 2400 : 13000;
        c.sent(e, bytes, rate > 0 ? double(bytes) / rate : 0);
        if (other) encoded(other_encoding(e));
        cells += e == GroupEncoding::cells ? 1 : 0;
        if (e == GroupEncoding::compact_zstd && first_compact == 0) first_compact = i + 1;
    }
    return first_compact;
}

TEST(EncodingChoice, MeasuredBothWaysNeitherIsSentToBeKnown) {
    // 1 Mbit/s: compact+zstd, measured but never sent, takes cells' link rate and is five times
    // dearer: it goes out first when exploring, some 80 groups in, not second.
    EncodingChooser slow;
    std::uint64_t cells = 0;
    EXPECT_GE(run_measuring_first(slow, 125e3, 200, cells), 40u);
    EXPECT_GT(slow.cost_per_triangle(GroupEncoding::compact_zstd), 0) << "measured";
    EXPECT_GT(slow.cost_per_triangle(GroupEncoding::cells), 0) << "measured";
    EXPECT_EQ(slow.chosen(GroupEncoding::cells), cells);
    // A link whose sends never block: cells while it is unknown (kProbeSends groups), then the
    // CPU decides, for compact+zstd.
    EncodingChooser fast;
    EXPECT_EQ(run_measuring_first(fast, 0, 200, cells), EncodingChooser::kProbeSends + 1);
    EXPECT_LT(cells, 200u / 8);
}

TEST(EncodingChoice, AServersOwnPacingIsTheLinkUntilOneIsSeen) {
    // serve --rate-mbps 100: compact+zstd from the first group (the prior, kCellsPayBelow), then
    // the CPU decides, for compact+zstd; at 1 Mbit/s cells from the first. Without the cap the
    // first groups probe the link as cells.
    EncodingChooser fast, slow;
    fast.set_link_cap(12.5e6);
    slow.set_link_cap(125e3);
    std::uint64_t cells = 0;
    EXPECT_EQ(run_measuring_first(fast, 12.5e6, 200, cells), 1u) << "compact+zstd from the first";
    EXPECT_EQ(cells, 0u);
    EXPECT_EQ(fast.cost_per_triangle(GroupEncoding::cells), 0)
        << "cells are not even measured on a link known to be fast";
    EXPECT_GE(run_measuring_first(slow, 125e3, 200, cells), 40u);
    // A link slower than the cap (a client that reads slowly) is what counts once seen.
    EncodingChooser capped;
    capped.set_link_cap(12.5e6);
    EXPECT_GT(run(capped, 125e3, 400), 400u - 400u / 8);
    EXPECT_NEAR(capped.bytes_per_s(), 125e3, 1.0);
}

TEST(EncodingChoice, ExploresTheOtherRarelyButAlways) {
    EncodingChooser c;
    const auto cells = run(c, 125e3, 1000);
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
    run(c, 0, 200);  // fast: compact
    const auto cells = run(c, 125e3, 400);
    std::printf("after the link fell to 1 Mbit/s: %llu of 400 groups as cells\n",
                (unsigned long long)cells);
    EXPECT_GT(cells, 300u);
}

// The link and the server overlap: at 100 Mbit/s compact+zstd's 6.5 bytes a triangle take
// 0.52 us, against the server's 0.3 + 0.35 us for cells and 0.3 + 0.13 for compact. Compact is then
// the sooner (0.52 against 0.65), though a sum of the two would charge it 0.95.
TEST(EncodingChoice, TheServerAndTheLinkOverlap) {
    EncodingChooser c;
    const auto cells = run(c, 12.5e6, 400);
    EXPECT_LT(cells, 400u / 8);
    EXPECT_NEAR(c.cost_per_triangle(GroupEncoding::compact_zstd), 0.52e-6, 0.01e-6);
    EXPECT_NEAR(c.cost_per_triangle(GroupEncoding::cells), 0.65e-6, 0.01e-6);
}

// Passes of a few triangles (a header each, and a while to find them) weigh by their triangles:
// they do not swamp what thousands of triangles showed.
// Gradients' voxels to a step first (cell_codec.h) only where the link bounds cells.
TEST(EncodingChoice, StepsPayWhereTheLinkBoundsCells) {
    EncodingChooser unknown;
    EXPECT_TRUE(unknown.steps_pay()) << "the link unknown: fewer bytes first";
    EncodingChooser fast;
    run(fast, 0, 400);
    EXPECT_FALSE(fast.steps_pay()) << "sends that never wait: bytes cost no time";
    // 1 Mbit/s: cells' 1.2 B a triangle take 9.6 us on the link, the client 2 us: the link.
    EncodingChooser slow;
    run(slow, 125e3, 400, 2e-6);
    EXPECT_TRUE(slow.steps_pay());
    // 30 Mbit/s: 0.32 us on the link, the server 0.65 us and the client 2: not the link.
    EncodingChooser client_bound;
    run(client_bound, 3.75e6, 400, 2e-6);
    EXPECT_FALSE(client_bound.steps_pay());
    // A link the server paces, before cells are measured: the prior (kCellsPayBelow).
    EncodingChooser paced_slow, paced_fast;
    paced_slow.set_link_cap(125e3);
    paced_fast.set_link_cap(12.5e6);
    EXPECT_TRUE(paced_slow.steps_pay());
    EXPECT_FALSE(paced_fast.steps_pay());
}

TEST(EncodingChoice, SendsTheSchedulerDelayedAreNotTheLinks) {
    // Every send takes 2 ms (a loaded machine's time slice); on a link that made them wait that
    // is a slow link, on one where the thread never blocked it says nothing of the link.
    const auto feed = [](EncodingChooser& c, bool waited) {
        std::uint64_t cells = 0;
        for (int i = 0; i < 200; ++i) {
            const auto [e, is_cells, bytes] = pick(c);
            cells += is_cells ? 1 : 0;
            c.sent(e, bytes, 2e-3, waited);
            c.decoded(e, 2000, 2000 * (is_cells ? 0.3e-6 : 0.026e-6));
        }
        return cells;
    };
    EncodingChooser waited, preempted;
    const auto slow_cells = feed(waited, true), fast_cells = feed(preempted, false);
    EXPECT_GT(waited.bytes_per_s(), 0.0);
    EXPECT_LT(waited.bytes_per_s(), 7e6);
    EXPECT_GT(slow_cells, 200u - 200u / 8);
    EXPECT_EQ(preempted.bytes_per_s(), 0.0);
    EXPECT_FALSE(preempted.steps_pay());
    EXPECT_LT(fast_cells, 200u / 8);
}

TEST(EncodingChoice, AClientThatReadsAsItDecodesIsNotASlowLink) {
    // A fast link to a busy page: it reads a group only once it decoded the one before, so each
    // send waits as long as the client's decoding of the group ahead (cells 5 us a triangle,
    // compact+zstd 0.4). Taken for the link's, those waits made the cells' 0.2 MB/s the rate, and
    // compact+zstd's bytes looked 5x dearer on that "link" than cells' decoding.
    EncodingChooser c;
    std::uint64_t cells = 0;
    double ahead_s = 0;  // the client's decoding of the group sent before
    for (int i = 0; i < 400; ++i) {
        const auto [e, is_cells, bytes] = pick(c);
        cells += is_cells ? 1 : 0;
        c.sent(e, bytes, std::max(ahead_s, 10e-6), ahead_s > 50e-6);
        ahead_s = 2000 * (is_cells ? 5e-6 : 0.4e-6);
        c.decoded(e, 2000, ahead_s);
    }
    std::printf("a client reading as it decodes: %llu of 400 groups as cells, rate seen %.3g B/s\n",
                (unsigned long long)cells, c.bytes_per_s());
    EXPECT_LT(cells, 400u / 8);
    // The same client behind a 1 Mbit/s link: the link's waits are far longer than its decoding.
    EncodingChooser slow;
    EXPECT_GT(run(slow, 125e3, 400, 5e-6), 400u - 400u / 8);
}

// Groups ready every 5 ms whose sends never wait (buffers absorb them) over a link that carries
// `link_rate` bytes a second (0: at once), and that a client holds back for `held` of the time
// (its receive window full); returns how many of `groups` went as cells.
std::uint64_t through_link(EncodingChooser& c, int groups, double link_rate, double held = 0,
                           bool tells = true) {
    std::uint64_t cells = 0, sent = 0;
    for (int i = 0; i < groups; ++i) {
        const double now = 0.005 * i;
        const double carried = link_rate > 0 ? link_rate * (1 - held) * now : 1e18;
        const auto acked = static_cast<std::uint64_t>(std::min(double(sent), carried));
        if (tells)
            c.ready_to_send(LinkProgress{0, acked, sent - acked, held * now}, now);
        else
            c.ready_to_send(std::nullopt, now);
        const auto [e, is_cells, bytes] = pick(c);
        cells += is_cells ? 1 : 0;
        c.sent(e, bytes, 0);
        sent += bytes;
    }
    return cells;
}

TEST(EncodingChoice, TheLinksProgressTellsItsRate) {
    // A link that delivered every byte before the next group was ready keeps up: the probe ends
    // after 2 groups found it empty.
    EncodingChooser fast;
    EXPECT_LE(through_link(fast, 8, 0), 2u);
    // 1 Mbit/s behind buffers that never make a send wait: its rate from the bytes acknowledged
    // while others were on their way, and cells throughout.
    EncodingChooser slow;
    EXPECT_GT(through_link(slow, 100, 125e3), 100u - 100u / 8);
    EXPECT_NEAR(slow.bytes_per_s(), 125e3, 125e3 * 0.05);
    // 100 Mbit/s behind the same buffers: known after two rates, then compact+zstd.
    EncodingChooser quick;
    EXPECT_LT(through_link(quick, 100, 12.5e6), 100u / 8);
    // A client that holds the bytes back (its window full) 90% of the time is not a slow link:
    // no rate is read from it.
    EncodingChooser held;
    through_link(held, 100, 12.5e6, 0.9);
    EXPECT_EQ(held.bytes_per_s(), 0.0);
    // A fast link whose receiver delays its last acknowledgement: a segment's bytes are always on
    // their way, which is no backlog.
    // Every look finds `unacked` bytes on their way, `acked` more acknowledged than the last.
    const auto looks = [](std::size_t unacked, std::uint64_t acked, bool same_host) {
        EncodingChooser c;
        for (int i = 0; i < 40; ++i) {
            c.ready_to_send(LinkProgress{0, acked * i, unacked, 0, same_host}, 0.005 * i);
            const GroupEncoding e = c.next();
            c.encoded(e, 2000, 3000, 1e-3, 1e-3);
            c.sent(e, 3000, 0);
        }
        return c.bytes_per_s();
    };
    EXPECT_EQ(looks(1448, 3000, false), 0.0);
    // A peer on this host: no link between, and bytes on their way wait for the CPUs.
    EXPECT_EQ(looks(50000, 1000, true), 0.0);
    EXPECT_NEAR(looks(50000, 1000, false), 1000 / 0.005, 1.0);  // the same, over a network
    // A connection that cannot tell: the sends' rules alone (8 groups as cells).
    EncodingChooser blind;
    EXPECT_EQ(through_link(blind, 8, 125e3, 0, false), 8u);
}

TEST(EncodingChoice, AClientsStallIsNotItsDecoding) {
    // The client's first compact+zstd report covers a stall (cold decoders, a loaded machine):
    // 6 us a triangle against cells' 3.5. Its next reports, 0.3 us, are what it can do.
    EncodingChooser c;
    c.ready_to_send(LinkProgress{0, 0, 0, 0, false}, 0);
    c.ready_to_send(LinkProgress{0, 0, 0, 0, false}, 0.001);
    for (int i = 0; i < 200; ++i) {
        const auto [e, is_cells, bytes] = pick(c);
        c.sent(e, bytes, 0);
        if (i == 0) {
            c.decoded(GroupEncoding::cells, 2000, 2000 * 3.5e-6);
            c.decoded(GroupEncoding::compact_zstd, 2000, 2000 * 6e-6);
        } else if (!is_cells) {
            c.decoded(GroupEncoding::compact_zstd, 2000, 2000 * 0.3e-6);
        }
        c.decoded(GroupEncoding::cells, 84, 0);  // a report of a tiny group: clock grain
    }
    EXPECT_EQ(c.next(), GroupEncoding::compact_zstd);
    EXPECT_NEAR(c.cost_per_triangle(GroupEncoding::cells), 3.5e-6, 1e-9);
    EXPECT_LT(c.chosen(GroupEncoding::cells), 200u / 8);
}

TEST(EncodingChoice, APeerOnThisHostGetsNoCellsUntilASendWaits) {
    EncodingChooser c;
    std::uint64_t cells = 0;
    for (int i = 0; i < 100; ++i) {
        c.ready_to_send(LinkProgress{0, 0, 0, 0, true}, 0.001 * i);
        const auto [e, is_cells, bytes] = pick(c, 0.001 * i);
        cells += is_cells ? 1 : 0;
        c.sent(e, bytes, 0);
    }
    EXPECT_EQ(cells, 0u);
    EXPECT_FALSE(c.wants_measure(GroupEncoding::cells));
    // A tunnel to a far client at 1 Mbit/s: once its buffers are full the sends wait.
    for (int i = 0; i < 300; ++i) {
        const auto [e, is_cells, bytes] = pick(c);
        if (c.wants_measure(GroupEncoding::cells))
            c.encoded(GroupEncoding::cells, 2000, 2400, 7e-4);
        c.sent(e, bytes, double(bytes) / 125e3);
        cells += is_cells ? 1 : 0;
    }
    EXPECT_GT(cells, 300u - 300u / 8);
}

TEST(EncodingChoice, ExploringIsSpacedInTime) {
    // A fast link, 400 groups in 0.4 s: cells are about 1.5x dearer (both bound by the server),
    // so without a clock they went every 24 groups; with one, at most once a second.
    const auto explored = [](bool clock) {
        EncodingChooser c;
        std::uint64_t cells = 0;
        for (int i = 0; i < 400; ++i) {
            const auto [e, is_cells, bytes] = pick(c, clock ? 0.001 * i : -1, 0.5e-6);
            cells += is_cells ? 1 : 0;
            c.sent(e, bytes, 0);
        }
        return cells;
    };
    const auto by_groups = explored(false), by_time = explored(true);
    std::printf("cells explored in 400 groups: %llu by groups, %llu with a clock\n",
                (unsigned long long)by_groups, (unsigned long long)by_time);
    EXPECT_GE(by_groups, 10u);
    EXPECT_LE(by_time, 10u);  // the probe's 8 and the first exploration
}

TEST(EncodingChoice, TinyPassesWeighByTheirTriangles) {
    EncodingChooser c;
    run(c, 0, 100);
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
