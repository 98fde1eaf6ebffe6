#include <gtest/gtest.h>
#include "common/camera.h"
TEST(Camera, Placeholder) { EXPECT_TRUE(true); }
