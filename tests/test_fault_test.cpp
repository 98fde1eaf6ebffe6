// The fault tests' hook is parsed once into a typed value (core/test_fault.h).
#include <gtest/gtest.h>

#include "core/test_fault.h"

namespace isowall {
namespace {

TEST(TestFault, EachKindParsesToItsActionMomentAndRank) {
    TestFault f = parse_test_fault("hang:2");
    EXPECT_EQ(f.action, FaultAction::hang);
    EXPECT_EQ(f.rank, 2);
    EXPECT_EQ(parse_test_fault("exit:3").action, FaultAction::exit);
    EXPECT_EQ(parse_test_fault("throw:0").action, FaultAction::throw_error);
    f = parse_test_fault("stop@migration:4");
    EXPECT_EQ(f.action, FaultAction::stop);
    EXPECT_EQ(f.moment, FaultMoment::migration);
    EXPECT_EQ(f.rank, 4);
    f = parse_test_fault("kill@init:1");
    EXPECT_EQ(f.action, FaultAction::kill);
    EXPECT_EQ(f.moment, FaultMoment::init);
    f = parse_test_fault("slow:tiles");
    EXPECT_EQ(f.action, FaultAction::slow);
    EXPECT_TRUE(f.on(1) && f.on(7));
    EXPECT_FALSE(f.on(0));
    f = parse_test_fault("late:tiles");
    EXPECT_EQ(f.action, FaultAction::late);
    EXPECT_TRUE(f.on(2));
    f = parse_test_fault("slow:3");
    EXPECT_TRUE(f.on(3));
    EXPECT_FALSE(f.on(2));
}

TEST(TestFault, AnythingElseIsNoFault) {
    for (const char* spec :
         {"", "hang", "hang:", "hang:x", "hang:2x", "jump:1", "stop@never:1", "stop:1",
          "pause@frame:1", ":1", "slow:tile", "slow@frame:tiles", "late@frame:1"}) {
        const TestFault f = parse_test_fault(spec);
        EXPECT_EQ(f.action, FaultAction::none) << spec;
    }
    EXPECT_EQ(parse_test_fault(nullptr).action, FaultAction::none);
}

TEST(TestFault, ASignalIsRaisedOnlyAtItsMoment) {
    // A stop at another moment, and a fault that is no signal, do nothing (the test goes on).
    raise_test_signal(parse_test_fault("stop@frame:1"), FaultMoment::load);
    raise_test_signal(parse_test_fault("hang:1"), FaultMoment::frame);
    raise_test_signal(TestFault{}, FaultMoment::none);
    SUCCEED();
}

}  // namespace
}  // namespace isowall
