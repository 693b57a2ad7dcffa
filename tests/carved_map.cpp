#include "carved_map.hpp"

namespace kartograf::testing {

void fill(Image<CellState>& cells, const CellRect& r, CellState state) {
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) cells(x, y) = state;
}

OccupancyGrid carve_map(int width, int height, std::initializer_list<CellRect> free_cells,
                        double resolution) {
  OccupancyGrid map;
  map.resolution = resolution;
  map.cells = Image<CellState>(width, height, CellState::occupied);
  for (const CellRect& r : free_cells) fill(map.cells, r, CellState::free);
  return map;
}

}  // namespace kartograf::testing
