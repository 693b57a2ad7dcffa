#include "semantic/grid_cabinets.hpp"

#include <algorithm>
#include <array>
#include <optional>
#include <utility>
#include <vector>

#include "semantic/grid_cells.hpp"

namespace kartograf::semantic::detail {
namespace {

// Wall cells a front may span across (a face and the noise behind it; a wall is thicker).
constexpr int kMaxFrontThickness = 2;
// Cells beyond a front's end where the wall line behind it is looked for (the first holds the
// cabinet's side).
constexpr int kRowsBeyondEnd = 4;
// Rows beyond an end that must show the line's face.
constexpr int kMinFaceRows = 2;
// Rows of a front, fewer than which is a speck.
constexpr int kMinFrontRows = 3;

// A direction to look at fronts from: `into` steps from the room into the cabinet, `along` runs
// along its front.
struct Frame {
  Eigen::Vector2i into, along;
  int depth(const Eigen::Vector2i& c) const { return c.dot(into); }
};

bool wall_at(const SemanticGrid& grid, const Eigen::Vector2i& c) {
  return seen_as(grid, c, SemanticClass::wall);
}

// What a cabinet's top and back hid: cells no view saw, or that it took for furniture or an
// unnamed obstacle.
bool hidden_or_furniture(const SemanticGrid& grid, const Eigen::Vector2i& c) {
  return unobserved(grid, c) || seen_as(grid, c, SemanticClass::furniture) ||
         unclassified_obstacle(grid, c);
}

// Whether c is a front's face: a wall cell with floor within 3 cells on the room's side, and
// behind it (after at most kMaxFrontThickness wall cells) a cell no view saw: the cabinet's top,
// where a wall between two rooms has the next room's floor or furniture.
bool front_face(const SemanticGrid& grid, const Eigen::Vector2i& c, const Frame& f) {
  if (!wall_at(grid, c) || wall_at(grid, c - f.into)) return false;
  bool room = false;
  for (int k = 1; k <= 3 && !room; ++k) room = seen_as(grid, c - k * f.into, SemanticClass::floor);
  if (!room) return false;
  Eigen::Vector2i behind = c + f.into;
  for (int k = 1; k < kMaxFrontThickness && wall_at(grid, behind); ++k) behind += f.into;
  return unobserved(grid, behind);
}

// A front: its faces in order along it, contiguous (a face may step one cell across).
using Front = std::vector<Eigen::Vector2i>;

// The fronts of one frame: runs of faces along `along`, each face within a cell (across) of the
// one before.
std::vector<Front> fronts_of(const SemanticGrid& grid, const Frame& f) {
  Image<std::uint8_t> taken(grid.width(), grid.height(), 0);
  std::vector<Front> fronts;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const Eigen::Vector2i start(col, row);
      if (taken(col, row) || !front_face(grid, start, f)) continue;
      // Start only at a run's first face: none one step back along it.
      bool first = true;
      for (int across = -1; across <= 1; ++across) {
        const Eigen::Vector2i before = start - f.along + across * f.into;
        first = first && !(grid.contains(before) && front_face(grid, before, f));
      }
      if (!first) continue;
      Front front{start};
      for (bool more = true; more;) {
        more = false;
        for (int across = -1; across <= 1 && !more; ++across) {
          const Eigen::Vector2i next = front.back() + f.along + across * f.into;
          if (grid.contains(next) && !taken(next.x(), next.y()) && front_face(grid, next, f))
            front.push_back(next), taken(next.x(), next.y()) = 1, more = true;
        }
      }
      if (static_cast<int>(front.size()) >= kMinFrontRows) fronts.push_back(std::move(front));
    }
  }
  return fronts;
}

// A front's two ends, each with the step that leads on beyond it along the front.
std::array<std::pair<Eigen::Vector2i, Eigen::Vector2i>, 2> ends_of(const Front& front,
                                                                   const Frame& f) {
  return {std::pair{front.front(), Eigen::Vector2i(-f.along)},
          std::pair{front.back(), Eigen::Vector2i(f.along)}};
}

// Whether the front's faces lie within kMaxFrontThickness cells across: a cabinet's front is
// straight, a line of faces stepping across the grid is not one.
bool straight(const Front& front, const Frame& f) {
  const auto [lo, hi] = std::minmax_element(
      front.begin(), front.end(),
      [&](const Eigen::Vector2i& a, const Eigen::Vector2i& b) { return f.depth(a) < f.depth(b); });
  return f.depth(*hi) - f.depth(*lo) <= kMaxFrontThickness;
}

// Whether the front's line runs on as wall through all kRowsBeyondEnd rows beyond either end
// (where a cabinet's side, and its front's last rows that the fills took, end): then it is a
// stretch of a longer wall, such as a building's wall at a notch, not a cabinet's front.
bool part_of_a_longer_wall(const SemanticGrid& grid, const Front& front, const Frame& f) {
  for (const auto& [end, step] : ends_of(front, f)) {
    int run = 0;
    for (Eigen::Vector2i c = end + step; run <= kRowsBeyondEnd; c += step, ++run) {
      if (!wall_at(grid, c) && !wall_at(grid, c - f.into) && !wall_at(grid, c + f.into)) break;
    }
    if (run > kRowsBeyondEnd) return true;
  }
  return false;
}

// The depth (from the front's median face) of the wall line seen beyond one of the front's ends,
// within (min_depth, max_depth]: a wall cell with floor on its side towards the front, at one
// depth in at least kMinFaceRows of the kRowsBeyondEnd rows beyond that end (the room runs on
// behind the front's plane up to the wall it stands against). The depth most rows show; none:
// no line.
std::optional<int> line_behind(const SemanticGrid& grid, const Front& front, const Frame& f,
                               int min_depth, int max_depth) {
  std::vector<int> depths;
  for (const Eigen::Vector2i& c : front) depths.push_back(f.depth(c));
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  const int face = depths[depths.size() / 2];
  std::vector<int> rows_at(static_cast<std::size_t>(max_depth + 1), 0);
  for (const auto& [end, step] : ends_of(front, f)) {
    const Eigen::Vector2i base = end + (face - f.depth(end)) * f.into;
    for (int k = 1; k <= kRowsBeyondEnd; ++k) {
      for (int d = min_depth + 1; d <= max_depth; ++d) {
        const Eigen::Vector2i c = base + k * step + d * f.into;
        if (wall_at(grid, c) && seen_as(grid, c - f.into, SemanticClass::floor)) {
          ++rows_at[static_cast<std::size_t>(d)];
          break;
        }
      }
    }
  }
  const auto best = std::max_element(rows_at.begin(), rows_at.end());
  if (*best < kMinFaceRows) return std::nullopt;
  return face + static_cast<int>(best - rows_at.begin());
}

// One row of a cabinet: its front's wall cells and the hidden cells behind them (furniture), and
// the wall line's cell at `line` depth; empty when the row holds anything else.
struct CabinetRow {
  std::vector<Eigen::Vector2i> furniture;
  std::optional<Eigen::Vector2i> line;
};

CabinetRow cabinet_row(const SemanticGrid& grid, const Eigen::Vector2i& face, const Frame& f,
                       int line) {
  CabinetRow row;
  Eigen::Vector2i c = face;
  for (; f.depth(c) < line && wall_at(grid, c) &&
         static_cast<int>(row.furniture.size()) < kMaxFrontThickness;
       c += f.into)
    row.furniture.push_back(c);
  for (; f.depth(c) < line; c += f.into) {
    if (!hidden_or_furniture(grid, c)) return {};
    row.furniture.push_back(c);
  }
  if (!unobserved(grid, c) && !wall_at(grid, c)) return {};
  row.line = c;
  return row;
}

}  // namespace

int cabinets_before_hidden_walls(SemanticGrid& grid, const CabinetLimits& limits,
                                 const TraversabilityWeights& weights,
                                 Image<std::uint8_t>& furniture) {
  const double cell_area = grid.resolution * grid.resolution;
  int cabinets = 0;
  for (const Eigen::Vector2i& into : kFourNeighbours) {
    const Frame f{into, Eigen::Vector2i(-into.y(), into.x())};
    for (const Front& front : fronts_of(grid, f)) {
      if (static_cast<int>(front.size()) > limits.max_extent_cells || !straight(front, f) ||
          part_of_a_longer_wall(grid, front, f))
        continue;
      const auto line = line_behind(grid, front, f, limits.min_depth_cells, limits.max_depth_cells);
      if (!line) continue;
      std::vector<Eigen::Vector2i> cells, wall;
      int rows = 0;
      for (const Eigen::Vector2i& face : front) {
        const CabinetRow row = cabinet_row(grid, face, f, *line);
        if (!row.line) continue;
        ++rows;
        cells.insert(cells.end(), row.furniture.begin(), row.furniture.end());
        if (unobserved(grid, *row.line)) wall.push_back(*row.line);
      }
      // Most of the front's rows reach the line through hidden cells only.
      if (4 * rows < 3 * static_cast<int>(front.size()) || rows < kMinFrontRows) continue;
      if (static_cast<double>(cells.size()) * cell_area > limits.max_area) continue;
      if (beside_door(grid, cells)) continue;
      ++cabinets;
      set_class(grid, cells, SemanticClass::furniture, weights.of(SemanticClass::furniture));
      for (const Eigen::Vector2i& c : cells) furniture(c.x(), c.y()) = 1;
      set_class(grid, wall, SemanticClass::wall, weights.of(SemanticClass::wall));
    }
  }
  return cabinets;
}

}  // namespace kartograf::semantic::detail
