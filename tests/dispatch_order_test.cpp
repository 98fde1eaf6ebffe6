// DispatchOrder (master/dispatch_order.h): which asking rank the master serves next.
#include "master/dispatch_order.h"

#include <gtest/gtest.h>

namespace isowall {
namespace {

TEST(DispatchOrder, OnArrivalServesAskersInTheOrderTheyAsked) {
    DispatchOrder d(5, Dispatch::arrival);
    d.begin_frame();
    d.served(1, true);
    d.clock(1, 0.001);  // a busy rank with an earlier clock holds nobody on arrival
    d.clock(3, 0.5);
    d.clock(2, 0.1);
    d.ask(3);
    d.ask(2);
    d.ask(3);  // asking twice is one request
    EXPECT_EQ(d.next(), 3);
    EXPECT_EQ(d.next(), 2);
    EXPECT_EQ(d.next(), std::nullopt);
    EXPECT_EQ(d.holds(), 0);
}

TEST(DispatchOrder, EmulatedServesTheEarliestClockOnceNoBusyRankIsEarlier) {
    DispatchOrder d(5, Dispatch::emulated);
    d.begin_frame();
    // Frame start: everyone at 0 asks; served in rank order among equal clocks.
    for (int r = 1; r <= 4; ++r) d.ask(r);
    for (int r = 1; r <= 4; ++r) {
        EXPECT_EQ(d.next(), r);
        d.served(r, true);
    }
    // Rank 3 ends its job at 0.020 s of its clock and asks first (in wall time); rank 2 at 0.010
    // asks after it: rank 2 is served first. Ranks 1 and 4 are still busy at known clock 0.
    d.clock(3, 0.020);
    d.ask(3);
    d.clock(2, 0.010);
    d.ask(2);
    EXPECT_EQ(d.next(), std::nullopt) << "ranks 1 and 4 may still end before 0.010";
    d.clock(1, 0.015);  // progress
    d.clock(4, 0.012);
    ASSERT_EQ(d.next(), 2);
    d.served(2, true);
    // Rank 2 is busy again at 0.010 < 0.020: rank 3 waits for it, then for rank 4 (0.012).
    EXPECT_EQ(d.next(), std::nullopt);
    d.clock(2, 0.030);
    EXPECT_EQ(d.next(), std::nullopt);
    d.clock(4, 0.025);
    EXPECT_EQ(d.next(), std::nullopt) << "rank 1 is at 0.015";
    d.served(1, false);  // rank 1 got nothing more: it no longer holds anyone
    EXPECT_EQ(d.next(), 3);
    EXPECT_GT(d.holds(), 0);
    // A new frame forgets every clock.
    d.begin_frame();
    EXPECT_EQ(d.clock_of(3), 0.0);
    EXPECT_EQ(d.holds(), 0);
}

TEST(DispatchOrder, ClocksOnlyMoveForward) {
    DispatchOrder d(3, Dispatch::emulated);
    d.clock(1, 0.5);
    d.clock(1, 0.2);  // an older progress message after a job end
    EXPECT_EQ(d.clock_of(1), 0.5);
}

}  // namespace
}  // namespace isowall
