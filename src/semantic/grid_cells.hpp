#pragma once
// Cell queries and updates shared by the semantic grid's steps (semantic_grid.cpp and the
// grid_*.cpp files).
#include <array>
#include <cmath>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "kartograf/semantic/semantic_grid.hpp"

namespace kartograf::semantic::detail {

// The steps to a cell's four edge neighbours.
inline const std::array<Eigen::Vector2i, 4> kFourNeighbours = {
    Eigen::Vector2i(1, 0), Eigen::Vector2i(-1, 0), Eigen::Vector2i(0, 1), Eigen::Vector2i(0, -1)};

// No view saw the cell (outside the grid: false).
inline bool unobserved(const SemanticGrid& grid, const Eigen::Vector2i& c) {
  return grid.contains(c) && std::isnan(grid.weight(c.x(), c.y()));
}

// A seen cell of class `wanted` (outside the grid: false).
inline bool seen_as(const SemanticGrid& grid, const Eigen::Vector2i& c, SemanticClass wanted) {
  return grid.contains(c) && grid.classes(c.x(), c.y()) == wanted && !unobserved(grid, c);
}

// Wall cells in a row from `cell` (not counted) in steps of `step`, up to `enough`.
inline int wall_run(const SemanticGrid& grid, Eigen::Vector2i cell, const Eigen::Vector2i& step,
                    int enough) {
  int run = 0;
  for (cell += step; run < enough && seen_as(grid, cell, SemanticClass::wall); cell += step) ++run;
  return run;
}

// Whether the wall cells through wall cell c along `across` are at most `max_cells`, with seen
// floor just beyond both ends: a wall the rooms on both its sides saw.
inline bool floor_beyond_both_faces(const SemanticGrid& grid, const Eigen::Vector2i& c,
                                    const Eigen::Vector2i& across, int max_cells) {
  const int ahead = wall_run(grid, c, across, max_cells);
  const int behind = wall_run(grid, c, -across, max_cells);
  return ahead + behind + 1 <= max_cells &&
         seen_as(grid, c + (ahead + 1) * across, SemanticClass::floor) &&
         seen_as(grid, c - (behind + 1) * across, SemanticClass::floor);
}

// Whether a door cell is a 4-neighbour of any of the cells: beside a door, an unseen pocket is a
// wall's inside behind its leaf, not what furniture hid.
inline bool beside_door(const SemanticGrid& grid, std::span<const Eigen::Vector2i> cells) {
  for (const Eigen::Vector2i& c : cells) {
    for (const Eigen::Vector2i& d : kFourNeighbours) {
      const Eigen::Vector2i n = c + d;
      if (grid.contains(n) && grid.classes(n.x(), n.y()) == SemanticClass::door) return true;
    }
  }
  return false;
}

// An obstacle the views could not name (weight 0, class unknown), as opposed to an unseen cell.
inline bool unclassified_obstacle(const SemanticGrid& grid, const Eigen::Vector2i& c) {
  return grid.contains(c) && grid.classes(c.x(), c.y()) == SemanticClass::unknown &&
         grid.weight(c.x(), c.y()) == 0.0f;
}

// Gives the cells class `c` with its weight.
inline void set_class(SemanticGrid& grid, std::span<const Eigen::Vector2i> cells, SemanticClass c,
                      float weight) {
  for (const Eigen::Vector2i& cell : cells) {
    grid.classes(cell.x(), cell.y()) = c;
    grid.weight(cell.x(), cell.y()) = weight;
  }
}

// Any run's two ends.
struct AnyEnds {
  bool operator()(const Eigen::Vector2i&, const Eigen::Vector2i&) const { return true; }
};

// The unobserved cells on row and column runs of unobserved cells with cells where is_end holds at
// both ends, longer than min_cells and at most max_cells, whose two ends `accept` takes (each cell
// once per run it lies on).
template <typename IsEnd, typename Accept = AnyEnds>
std::vector<Eigen::Vector2i> unobserved_runs_between(const SemanticGrid& grid, const IsEnd& is_end,
                                                     int min_cells, int max_cells,
                                                     const Accept& accept = {}) {
  std::vector<Eigen::Vector2i> inside;
  for (const Eigen::Vector2i& step : {Eigen::Vector2i(1, 0), Eigen::Vector2i(0, 1)}) {
    for (int row = 0; row < grid.height(); ++row) {
      for (int col = 0; col < grid.width(); ++col) {
        const Eigen::Vector2i start(col, row);
        if (!is_end(start) || !unobserved(grid, start + step)) continue;
        Eigen::Vector2i c = start + step;
        int run = 0;
        while (unobserved(grid, c) && run <= max_cells) c += step, ++run;
        if (run <= min_cells || run > max_cells || !grid.contains(c) || !is_end(c) ||
            !accept(start, c))
          continue;
        for (Eigen::Vector2i k = start + step; k != c; k += step) inside.push_back(k);
      }
    }
  }
  return inside;
}

}  // namespace kartograf::semantic::detail
