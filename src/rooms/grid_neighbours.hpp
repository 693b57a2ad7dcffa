#pragma once
// The 8-neighbours of a cell of a row-major grid, as flat indices, clipped at the grid's edges.
#include <cstdint>

namespace kartograf::rooms::detail {

template <class Visit>
void for_each_neighbour8(std::uint32_t i, int width, int height, Visit&& visit) {
  const int x = static_cast<int>(i % static_cast<std::uint32_t>(width));
  const int y = static_cast<int>(i / static_cast<std::uint32_t>(width));
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int nx = x + dx, ny = y + dy;
      if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
      visit(static_cast<std::uint32_t>(ny * width + nx));
    }
  }
}

}  // namespace kartograf::rooms::detail
