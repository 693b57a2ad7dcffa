// The exact Euclidean distance transform (geometry/distance_transform.hpp) against brute force:
// every squared distance equal, on random masks of every shape and density.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "kartograf/geometry/distance_transform.hpp"

namespace kartograf {
namespace {

Image<std::int64_t> brute_force(const Image<std::uint8_t>& mask) {
  Image<std::int64_t> result(mask.width(), mask.height(), -1);
  for (int y = 0; y < mask.height(); ++y) {
    for (int x = 0; x < mask.width(); ++x) {
      for (int v = 0; v < mask.height(); ++v) {
        for (int u = 0; u < mask.width(); ++u) {
          if (mask(u, v) != 0) continue;
          const std::int64_t d = std::int64_t{u - x} * (u - x) + std::int64_t{v - y} * (v - y);
          if (result(x, y) < 0 || d < result(x, y)) result(x, y) = d;
        }
      }
    }
  }
  return result;
}

TEST(DistanceTransform, EqualsBruteForceOnRandomMasks) {
  std::mt19937 rng(20261126);
  std::uniform_int_distribution<int> side(1, 40);
  std::uniform_real_distribution<double> density(0.0, 0.3);
  for (int trial = 0; trial < 300; ++trial) {
    Image<std::uint8_t> mask(side(rng), side(rng));
    std::bernoulli_distribution zero(trial % 10 == 0 ? 0.002 : density(rng));
    for (std::uint8_t& m : mask.pixels()) m = zero(rng) ? 0 : 255;
    const Image<std::int64_t> expected = brute_force(mask);
    const Image<std::int64_t> actual = geometry::squared_distance_to_zero(mask);
    ASSERT_TRUE(
        std::equal(expected.pixels().begin(), expected.pixels().end(), actual.pixels().begin()))
        << "trial " << trial << ": " << mask.width() << " x " << mask.height();
  }
}

TEST(DistanceTransform, KnownAnswersAndMasksWithoutZero) {
  Image<std::uint8_t> row(5, 1, 1);
  row(0, 0) = 0;
  const Image<float> distance = geometry::distance_to_zero(row);
  for (int x = 0; x < 5; ++x) EXPECT_EQ(distance(x, 0), static_cast<float>(x));
  Image<std::uint8_t> corner(4, 3, 1);
  corner(3, 2) = 0;
  EXPECT_EQ(geometry::squared_distance_to_zero(corner)(0, 0), 9 + 4);
  EXPECT_EQ(geometry::distance_to_zero(corner)(0, 0), std::sqrt(13.0f));
  const Image<std::uint8_t> none(3, 2, 7);
  const Image<std::int64_t> squared = geometry::squared_distance_to_zero(none);
  for (const std::int64_t d : squared.pixels()) EXPECT_EQ(d, -1);
  const Image<float> distance_none = geometry::distance_to_zero(none);
  for (const float d : distance_none.pixels()) EXPECT_TRUE(std::isinf(d));
  EXPECT_TRUE(geometry::distance_to_zero(Image<std::uint8_t>()).empty());
}

}  // namespace
}  // namespace kartograf
