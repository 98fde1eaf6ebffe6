// The newest-request mailbox (core/newest_request.h): the newest of several waiting requests
// wins, a put raises the stop flag a worker reads, take lowers it, and close ends a waiting take.
#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <thread>

#include "core/newest_request.h"

namespace isowall {
namespace {

TEST(NewestRequest, TheNewestOfWaitingRequestsWinsAndTakeLowersTheStopFlag) {
    NewestRequest<int> box;
    EXPECT_FALSE(box.stop_flag().load());
    box.put(1);
    box.put(2);
    EXPECT_TRUE(box.stop_flag().load()) << "a request waits: the work in progress should end";
    EXPECT_EQ(box.take(), 2);
    EXPECT_FALSE(box.stop_flag().load());
    box.put(3);  // arrives while 2 is worked on
    EXPECT_TRUE(box.stop_flag().load());
    EXPECT_EQ(box.take(), 3);
}

TEST(NewestRequest, ATakeWaitsForAPutFromAnotherThread) {
    NewestRequest<int> box;
    auto taken = std::async(std::launch::async, [&] { return box.take(); });
    EXPECT_EQ(taken.wait_for(std::chrono::milliseconds(50)), std::future_status::timeout);
    box.put(7);
    EXPECT_EQ(taken.get(), 7);
}

TEST(NewestRequest, CloseEndsAWaitingTakeAndRaisesTheStopFlag) {
    NewestRequest<int> box;
    auto taken = std::async(std::launch::async, [&] { return box.take(); });
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    box.close();
    EXPECT_EQ(taken.get(), std::nullopt);
    EXPECT_TRUE(box.stop_flag().load());
    box.put(1);  // after the close: never taken
    EXPECT_EQ(box.take(), std::nullopt);
}

}  // namespace
}  // namespace isowall
