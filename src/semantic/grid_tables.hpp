#pragma once
// Tables seen by their legs (a step of build_semantic_grid). A table's top is seen only near it:
// the camera looks across it from a little above, and grazing views drop it; its edges join only
// where they are seen. Its legs are seen from everywhere: posts standing on the floor at the
// corners of a rectangle, under a top no ray passes through.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "kartograf/semantic/semantic_grid.hpp"
#include "semantic/grid_free_space.hpp"

namespace kartograf::semantic::detail {

// A post standing on the floor, a few cells across at most: its cells, and its highest point
// above the floor [m].
struct TableLeg {
  std::vector<Eigen::Vector2i> cells;
  double top = 0;
  Eigen::Vector2d centre() const;
};

// How far apart a table's legs stand [cells], and how large its top may be [cells^2].
struct LegLimits {
  double min_side = 0, max_side = 0, max_area = 0;
};

// A table's top: the rectangle around its legs' cells, corners in cell coordinates (a cell's
// centre at its indices), in order around it.
using TableTop = std::array<Eigen::Vector2d, 4>;

// A table found by its legs: its top, and which legs stand under it.
struct LegTable {
  TableTop top;
  std::vector<int> legs;
};

// Rectangles with a leg at three or four of their corners (sides at right angles within 8
// degrees), those with four first, then the smallest; each leg stands under one table, and no
// other leg stands a cell or more inside one (the legs of two tables in a row make a larger
// rectangle too).
std::vector<LegTable> tables_on_legs(std::span<const TableLeg> legs, const LegLimits& limits);

// Fills the floor under each table of tables_on_legs whose top the rays did not pass through
// (under_solid_top, at the heights around its legs' median top), `furniture` marking the cells;
// walls, doors and what no view saw keep their class. Returns the tables filled.
std::vector<LegTable> fill_tables_on_legs(SemanticGrid& grid, std::span<const TableLeg> legs,
                                          const LegLimits& limits, const BandFreeSpace& free_space,
                                          float weight, Image<std::uint8_t>& furniture);

// The floor a fill joined to a table found by all four legs (its top is where they stand): in
// each piece of furniture cells (8-neighbours) that holds such a table, the cells not `marked`
// (no obstacle seen there: what the fill made furniture) more than a cell outside every table's
// top (on three legs too) and more than 3 cells from a wall are floor again. The fill had joined
// the table's outline to lines of a depth edge's points along the views' rays, and its hull covered
// the floor between them; near a wall the fill is left (floor before a wall's face makes it a
// cabinet's front for the rules after). Returns how many cells.
int trim_fills_around_tables(SemanticGrid& grid, std::span<const LegTable> tables,
                             const Image<std::uint8_t>& marked, float floor_weight,
                             Image<std::uint8_t>& furniture);

}  // namespace kartograf::semantic::detail
