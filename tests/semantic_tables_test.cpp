// Tables seen by their legs, through the grid step's internal header (semantic/grid_tables.hpp):
// which posts make a table, and which of a fill's cells around a table are floor again. The
// whole step, on rays cast in a scene, is tested in semantic_free_space_test.cpp.
#include <gtest/gtest.h>

#include <vector>

#include "kartograf/semantic/semantic_grid.hpp"
#include "semantic/grid_tables.hpp"

namespace kartograf::semantic::detail {
namespace {

using C = SemanticClass;

// A post of 2 x 2 cells with its lower-left cell at (x, y).
TableLeg leg_at(int x, int y) {
  return {{{x, y}, {x + 1, y}, {x, y + 1}, {x + 1, y + 1}}, 0.72};
}

// Legs 6-50 cells apart, tops up to 400 cells.
constexpr LegLimits kLimits{6, 50, 400};

TEST(TablesOnLegs, FourLegsAtTheCornersMakeOneTableAroundThem) {
  const std::vector<TableLeg> legs = {leg_at(10, 10), leg_at(30, 10), leg_at(10, 24),
                                      leg_at(30, 24)};
  const std::vector<LegTable> tables = tables_on_legs(legs, kLimits);
  ASSERT_EQ(tables.size(), 1u);
  EXPECT_EQ(tables[0].legs.size(), 4u);
  Eigen::Vector2d lo = tables[0].top[0], hi = tables[0].top[0];
  for (const Eigen::Vector2d& corner : tables[0].top)
    lo = lo.cwiseMin(corner), hi = hi.cwiseMax(corner);
  EXPECT_NEAR(lo.x(), 10, 1e-9);  // the legs' outer cells
  EXPECT_NEAR(lo.y(), 10, 1e-9);
  EXPECT_NEAR(hi.x(), 31, 1e-9);
  EXPECT_NEAR(hi.y(), 25, 1e-9);
}

TEST(TablesOnLegs, ThreeLegsAtRightAnglesMakeATableWithItsFourthCorner) {
  const std::vector<TableLeg> legs = {leg_at(10, 10), leg_at(30, 10), leg_at(10, 24)};
  const std::vector<LegTable> tables = tables_on_legs(legs, kLimits);
  ASSERT_EQ(tables.size(), 1u);
  EXPECT_EQ(tables[0].legs.size(), 3u);
}

TEST(TablesOnLegs, PostsNotAtARectanglesCornersMakeNone) {
  // Not at a right angle (the third 8 cells off it), too close, too far apart.
  EXPECT_TRUE(tables_on_legs({{leg_at(10, 10), leg_at(30, 10), leg_at(18, 24)}}, kLimits).empty());
  EXPECT_TRUE(tables_on_legs({{leg_at(10, 10), leg_at(14, 10), leg_at(10, 14)}}, kLimits).empty());
  EXPECT_TRUE(tables_on_legs({{leg_at(0, 0), leg_at(60, 0), leg_at(0, 20)}}, kLimits).empty());
}

TEST(TablesOnLegs, ALegInsideARectangleLeavesItToTheSmallerTables) {
  // Two tables in a row (legs 10 cells apart along x, 12 across) whose inner legs stand apart: the
  // large rectangle over both holds no leg inside, but each table's own comes first.
  std::vector<TableLeg> legs;
  for (const int x : {0, 10, 14, 24})
    for (const int y : {0, 12}) legs.push_back(leg_at(x, y));
  const std::vector<LegTable> tables = tables_on_legs(legs, kLimits);
  ASSERT_EQ(tables.size(), 2u);
  for (const LegTable& table : tables) {
    Eigen::Vector2d lo = table.top[0], hi = table.top[0];
    for (const Eigen::Vector2d& corner : table.top)
      lo = lo.cwiseMin(corner), hi = hi.cwiseMax(corner);
    EXPECT_NEAR(hi.x() - lo.x(), 11, 1e-9);
  }
  // A fifth leg inside: no rectangle around it.
  EXPECT_TRUE(tables_on_legs({{leg_at(10, 10), leg_at(30, 10), leg_at(10, 24), leg_at(30, 24),
                               leg_at(20, 17)}},
                             kLimits)
                  .empty());
}

// A 60 x 40 grid of floor with a wall along its top row.
SemanticGrid floor_grid() {
  SemanticGrid grid;
  grid.classes = Image<SemanticClass>(60, 40, C::floor);
  grid.weight = Image<float>(60, 40, 1.0f);
  for (int x = 0; x < 60; ++x) grid.classes(x, 39) = C::wall, grid.weight(x, 39) = 0.0f;
  return grid;
}

void make_furniture(SemanticGrid& grid, Image<std::uint8_t>& furniture, int x0, int x1, int y0,
                    int y1) {
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x)
      grid.classes(x, y) = C::furniture, grid.weight(x, y) = 0.0f, furniture(x, y) = 1;
}

TEST(TablesOnLegs, AFillJoinedToATableIsFloorAgainBeyondItsTop) {
  SemanticGrid grid = floor_grid();
  Image<std::uint8_t> furniture(60, 40, 0);
  make_furniture(grid, furniture, 10, 20, 10, 18);  // the table's top, filled
  Image<std::uint8_t> marked = furniture;           // as the views saw it
  make_furniture(grid, furniture, 21, 40, 12, 16);  // the fill's hull beyond it
  make_furniture(grid, furniture, 41, 42, 12, 16);  // an obstacle seen at the hull's far end
  for (int y = 12; y <= 16; ++y) marked(41, y) = marked(42, y) = 1;
  make_furniture(grid, furniture, 25, 30, 30, 38);  // filled cells beside the wall
  make_furniture(grid, furniture, 25, 30, 17, 29);  // joining them to the fill beyond the table
  make_furniture(grid, furniture, 50, 55, 2, 6);    // another piece's fill, not joined
  const LegTable table{{Eigen::Vector2d(10, 10), Eigen::Vector2d(20, 10), Eigen::Vector2d(20, 18),
                        Eigen::Vector2d(10, 18)},
                       {0, 1, 2, 3}};
  // Found by three legs, its fourth corner a guess: the fill beyond it stays.
  LegTable on_three_legs = table;
  on_three_legs.legs.pop_back();
  SemanticGrid untrimmed = grid;
  Image<std::uint8_t> untouched = furniture;
  EXPECT_EQ(trim_fills_around_tables(untrimmed, {{on_three_legs}}, marked, 1.0f, untouched), 0);
  // A table on three legs at the fill's far end: its top keeps the fill under and beside it.
  LegTable further = on_three_legs;
  for (Eigen::Vector2d& corner : further.top) corner.x() += 22;  // x 32-42, y 10-18
  const std::vector<LegTable> tables = {table, further};
  const int trimmed = trim_fills_around_tables(grid, tables, marked, 1.0f, furniture);
  EXPECT_EQ(grid.classes(15, 14), C::furniture);  // the table
  EXPECT_EQ(grid.classes(21, 14), C::furniture);  // a cell beyond its top: its overhang
  EXPECT_EQ(grid.classes(28, 14), C::floor);      // the fill beyond it
  EXPECT_EQ(furniture(28, 14), 0);
  EXPECT_EQ(grid.classes(31, 14), C::furniture);  // a cell beside the second table's top
  EXPECT_EQ(grid.classes(41, 14), C::furniture);  // what the views saw stays
  EXPECT_EQ(grid.classes(27, 25), C::floor);
  EXPECT_EQ(grid.classes(27, 37), C::furniture);  // within 3 cells of the wall: a front's floor
  EXPECT_EQ(grid.classes(52, 4), C::furniture);   // not joined to the table
  EXPECT_EQ(trimmed, 9 * 5 + 6 * 19);             // 22-30 x 12-16 and 25-30 x 17-35
}

}  // namespace
}  // namespace kartograf::semantic::detail
