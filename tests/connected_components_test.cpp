// Connected-component labelling (core/connected_components.hpp) on a hand-made mask with
// hand-computed answers.
#include <gtest/gtest.h>

#include <cstdint>

#include "kartograf/core/connected_components.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf {
namespace {

TEST(EvalConnectedComponents, NumbersRegionsInRasterOrderAndDropsSpecks) {
  // Region a (top left, 4 px) touches region b (5 px) only diagonally; c is a 1-px speck; d
  // (2 px) starts on row 0 to the right of a, so it is numbered before b.
  const char* rows[] = {
      "aa..d",  //
      "aa..d",  //
      "..b..",  //
      "..bb.",  //
      "c.bb.",  //
  };
  Image<std::uint8_t> mask(5, 5, 0);
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 5; ++x) mask(x, y) = rows[y][x] != '.';
  }
  const LabelImage four = label_connected_components(mask, {Connectivity::four, 2});
  EXPECT_EQ(four(0, 0), 1);  // a
  EXPECT_EQ(four(4, 0), 2);  // d
  EXPECT_EQ(four(2, 2), 3);  // b
  EXPECT_EQ(four(3, 4), 3);
  EXPECT_EQ(four(0, 4), 0);  // c: a speck of 1 < 2 pixels
  EXPECT_EQ(four(2, 0), 0);  // background
  const LabelImage eight = label_connected_components(mask, {Connectivity::eight, 1});
  EXPECT_EQ(eight(0, 0), 1);  // a and b joined through the diagonal, d stays apart
  EXPECT_EQ(eight(2, 2), 1);
  EXPECT_EQ(eight(4, 0), 2);
  EXPECT_EQ(eight(0, 4), 3);  // c kept with min_pixels 1
  EXPECT_THROW(label_connected_components(mask, {Connectivity::four, 0}), Error);
}

}  // namespace
}  // namespace kartograf
