#pragma once
// Occupancy maps with rectangles of free space carved out of an occupied map: no io, so the
// device tests (laser scans) can use them as well as the room segmentation tests.
#include <initializer_list>

#include "kartograf/core/occupancy_grid.hpp"

namespace kartograf::testing {

// Cells [x0, x1) x [y0, y1).
struct CellRect {
  int x0, y0, x1, y1;
};

// Sets the cells of `r` to `state`.
void fill(Image<CellState>& cells, const CellRect& r, CellState state);

// An occupied map of width x height cells at `resolution` with the rectangles set free.
OccupancyGrid carve_map(int width, int height, std::initializer_list<CellRect> free_cells,
                        double resolution = 0.05);

}  // namespace kartograf::testing
