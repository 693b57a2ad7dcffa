// The colour-to-depth registration check (registration/colour_registration.hpp) on made-up frames:
// boxes before a wall, painted where the depth has them or moved sideways off them. The real
// sets' verdicts: colour_registration_real_test.cpp.
#include "kartograf/registration/colour_registration.hpp"

#include <gtest/gtest.h>

#include <utility>

#include "kartograf/core/error.hpp"

namespace kartograf::registration {
namespace {

constexpr int kWidth = 160, kHeight = 120;

bool in_box(int x, int y) {
  return x % 40 >= 10 && x % 40 < 30 && y % 40 >= 10 && y % 40 < 30;
}

// Twelve boxes 1 m away before a wall 2 m away (millimetres).
DepthImage boxes_depth() {
  DepthImage depth(kWidth, kHeight, 2000);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      if (in_box(x, y)) depth(x, y) = 1000;
  return depth;
}

// The boxes dark on the light wall, painted (dx, dy) pixels from where the depth has them.
RgbImage boxes_colour(int dx = 0, int dy = 0) {
  RgbImage colour(kWidth, kHeight, Rgb8{200, 190, 180});
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      if (x - dx >= 0 && y - dy >= 0 && in_box(x - dx, y - dy)) colour(x, y) = Rgb8{40, 50, 60};
  return colour;
}

ColourRegistrationParams few_steps() {
  ColourRegistrationParams params;
  params.min_steps = 500;  // a box frame has about 900 depth steps
  params.max_frames = 3;
  return params;
}

TEST(ColourRegistration, ColourEdgesOnTheDepthEdgesAreRegistered) {
  ColourRegistrationCheck check(few_steps());
  check.add(boxes_depth(), boxes_colour());
  EXPECT_EQ(check.verdict(), ColourRegistration::registered);
  EXPECT_GT(check.contrast(), 2.0);
  EXPECT_TRUE(check.done());
}

TEST(ColourRegistration, ColourMovedOffTheDepthEdgesIsNotRegistered) {
  // As 7-Scenes' colour lies 5-12 pixels off its depth edges, both ways.
  for (const auto& [dx, dy] : {std::pair{5, 4}, std::pair{-7, -6}}) {
    ColourRegistrationCheck check(few_steps());
    check.add(boxes_depth(), boxes_colour(dx, dy));
    EXPECT_EQ(check.verdict(), ColourRegistration::not_registered) << dx << ", " << dy;
    EXPECT_LT(check.contrast(), 0.5) << dx << ", " << dy;
  }
}

TEST(ColourRegistration, WaitsForEnoughDepthStepsAndStopsAfterItsFrames) {
  ColourRegistrationParams params = few_steps();
  params.min_steps = 2000;  // more than one frame has
  ColourRegistrationCheck check(params);
  check.add(boxes_depth(), boxes_colour());
  EXPECT_EQ(check.verdict(), ColourRegistration::undecided);
  EXPECT_FALSE(check.done());
  check.add(boxes_depth(), boxes_colour());
  check.add(boxes_depth(), boxes_colour());
  EXPECT_EQ(check.verdict(), ColourRegistration::registered);

  // A wall alone has no depth step: no verdict, and none after max_frames.
  ColourRegistrationCheck flat(few_steps());
  for (int i = 0; i < 5; ++i) flat.add(DepthImage(kWidth, kHeight, 2000), boxes_colour());
  EXPECT_EQ(flat.verdict(), ColourRegistration::undecided);
  EXPECT_EQ(flat.contrast(), 0.0);
  EXPECT_TRUE(flat.done());
}

TEST(ColourRegistration, RejectsMismatchedSizesAndBadParameters) {
  ColourRegistrationCheck check(few_steps());
  EXPECT_THROW(check.add(boxes_depth(), RgbImage(kWidth / 2, kHeight / 2)), Error);
  ColourRegistrationParams params;
  params.unregistered_contrast = 2.0;  // above the registered one
  EXPECT_THROW(ColourRegistrationCheck{params}, Error);
  params = {};
  params.depth_step = 0;
  EXPECT_THROW(ColourRegistrationCheck{params}, Error);
  params = {};
  params.max_frames = 0;
  EXPECT_THROW(ColourRegistrationCheck{params}, Error);
}

}  // namespace
}  // namespace kartograf::registration
