// The speed bound (registration/speed_bound.hpp): what it learns from a robot's steps, when it
// starts to bound, and how the bound widens with the frames since the last measured step.
#include "kartograf/registration/speed_bound.hpp"

#include <gtest/gtest.h>

namespace kartograf::registration {
namespace {

constexpr double kMargin = 2;
constexpr double kLeastChange = 0.05;

TEST(SpeedBound, AdmitsEveryStepUntilItHasSeenTheSpeedChange) {
  SpeedBound bound(kMargin, kLeastChange);
  // At rest, then cruising at 0.5 m a frame from frame 10 (the change into frame 10 was missed):
  // no change above the least is seen, so nothing is bounded yet.
  for (std::size_t frame = 1; frame <= 5; ++frame) bound.learn(frame, 0.0);
  for (std::size_t frame = 10; frame <= 15; ++frame) bound.learn(frame, 0.5);
  EXPECT_FALSE(bound.ready());
  EXPECT_TRUE(bound.admits(16, 0.0));
  EXPECT_TRUE(bound.admits(16, 2.0));
}

TEST(SpeedBound, LearnsTheLargestChangeBetweenConsecutiveFramesOnly) {
  SpeedBound bound(kMargin, kLeastChange);
  bound.learn(1, 0.1);
  bound.learn(2, 0.3);  // +0.2 in one frame
  bound.learn(4, 0.9);  // +0.6 over two frames: not a one-frame change
  bound.learn(5, 0.8);
  EXPECT_TRUE(bound.ready());
  EXPECT_DOUBLE_EQ(bound.largest_change_m(), 0.2);
}

TEST(SpeedBound, BoundsTheStepByTheMarginTimesTheChangePerFrameSinceTheLastMeasured) {
  SpeedBound bound(kMargin, kLeastChange);
  bound.learn(1, 0.2);
  bound.learn(2, 0.4);
  bound.learn(3, 0.6);
  bound.learn(4, 0.8);  // largest change 0.2: one frame later, 0.8 +- 0.4
  const auto [low, high] = bound.admitted(5);
  EXPECT_NEAR(low, 0.4, 1e-9);
  EXPECT_NEAR(high, 1.2, 1e-9);
  EXPECT_TRUE(bound.admits(5, 1.15));
  EXPECT_TRUE(bound.admits(5, 0.45));
  EXPECT_FALSE(bound.admits(5, 0.3));  // a tile over on a checkered floor
  EXPECT_FALSE(bound.admits(5, 1.3));
  // Two frames after the last measured step the speed may have changed twice as much.
  EXPECT_TRUE(bound.admits(6, 0.1));
  EXPECT_FALSE(bound.admits(6, 1.7));
}

TEST(SpeedBound, IsOffWithAZeroMargin) {
  SpeedBound bound(0, kLeastChange);
  bound.learn(1, 0.0);
  bound.learn(2, 0.5);
  EXPECT_FALSE(bound.ready());
  EXPECT_TRUE(bound.admits(3, 5.0));
}

}  // namespace
}  // namespace kartograf::registration
