// The CPU backend's four-lane helpers (src/compute/cpu/lanes.hpp) that kernels rely on to repeat
// a rule's float operations exactly: per-lane minimum and maximum choosing as std::min and
// std::max do (NaN lanes included), and a row's left neighbours.
#include "compute/cpu/lanes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace kartograf {
namespace {

using compute::detail::Lanes;

// Bitwise: NaN must come out where std::min or std::max gives NaN, and -0 where it gives -0.
void expect_same_bits(float expected, float actual) {
  EXPECT_EQ(std::signbit(expected), std::signbit(actual));
  EXPECT_EQ(std::isnan(expected), std::isnan(actual));
  if (!std::isnan(expected)) {
    EXPECT_EQ(expected, actual);
  }
}

TEST(CpuLanes, MinAndMaxChooseAsTheStandardLibraryDoes) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Pairs where a naive choice differs from std::min or std::max: NaN on either side, and a
  // signed zero against the other.
  const Lanes a{nan, 1.0f, -0.0f, 0.0f};
  const Lanes b{2.0f, nan, 0.0f, -0.0f};
  const Lanes minimum = compute::detail::min_of(a, b), maximum = compute::detail::max_of(a, b);
  for (int j = 0; j < 4; ++j) {
    expect_same_bits(std::min(a[j], b[j]), minimum[j]);
    expect_same_bits(std::max(a[j], b[j]), maximum[j]);
  }
}

TEST(CpuLanes, ShiftInGivesEachLaneItsLeftNeighbour) {
  const Lanes row = compute::detail::shift_in(Lanes{0, 1, 2, 3}, Lanes{4, 5, 6, 7});
  for (int j = 0; j < 4; ++j) EXPECT_EQ(row[j], 3.0f + j);
}

}  // namespace
}  // namespace kartograf
