// The map's floor level from the heights of the points the views labelled floor: the lowest level
// holding a large share of them, not their median, which a table top taken for the floor by the
// views that saw no floor can carry (7-Scenes' kitchen: 0.75 m up).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "kartograf/semantic/labelled_views.hpp"

namespace kartograf::semantic {
namespace {

// n heights about `level`, with 1 cm of noise.
void add_level(std::vector<double>& heights, double level, int n, std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int i = 0; i < n; ++i) heights.push_back(level + noise(rng));
}

TEST(SemanticFloorLevel, IsTheLowestLevelTheViewsCalledFloor) {
  std::mt19937 rng(3);
  std::vector<double> one;
  add_level(one, 0.0, 1000, rng);
  std::vector<double> sorted = one;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_DOUBLE_EQ(*floor_level(one), sorted[sorted.size() / 2]);  // one level: the median

  std::vector<double> table = one;
  add_level(table, 0.75, 1500, rng);  // more table top than floor
  EXPECT_NEAR(*floor_level(table), 0.0, 0.01);

  std::vector<double> strays = table;
  add_level(strays, -0.5, 60, rng);  // 2 % below: noise, no level
  EXPECT_NEAR(*floor_level(strays), 0.0, 0.01);

  std::vector<double> far = table;  // a garbage height either way bins nothing
  far.push_back(1e9);
  far.push_back(-1e9);
  EXPECT_NEAR(*floor_level(far), 0.0, 0.01);

  std::vector<double> small_floor;
  add_level(small_floor, 0.0, 100, rng);  // 6 %: too few to be a level
  add_level(small_floor, 0.75, 1500, rng);
  EXPECT_NEAR(*floor_level(small_floor), 0.75, 0.01);

  EXPECT_FALSE(floor_level({}).has_value());
}

}  // namespace
}  // namespace kartograf::semantic
