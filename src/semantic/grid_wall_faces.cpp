#include "semantic/grid_wall_faces.hpp"

#include <algorithm>
#include <array>
#include <optional>
#include <vector>

#include "semantic/grid_cells.hpp"
#include "semantic/quantile.hpp"

namespace kartograf::semantic::detail {
namespace {

// The face is measured on the wall points of this many cells on either side of the one judged,
// along the face, in the rows of cells on both sides of it and one row further into the wall.
constexpr int kFaceStretch = 3;
// ... and needs this many of them within a cell of the face.
constexpr std::size_t kMinFacePoints = 20;
// Layers of cells a face may move through: 4 cells, 20 cm, twice the spread of a face seen
// from 6 m (the synthetic camera's depth steps there are 11 cm).
constexpr int kMaxFaceRounds = 4;

// One wall cell facing one floor cell: the boundary between them and the axes there [m].
struct Boundary {
  Eigen::Vector2d point, out, along;  // out: from the wall cell to the floor cell
};

Boundary boundary_between(const SemanticGrid& grid, const Eigen::Vector2i& wall,
                          const Eigen::Vector2i& floor) {
  const Eigen::Vector2d a = grid.cell_center(wall), b = grid.cell_center(floor);
  const Eigen::Vector2d out = (b - a).normalized();
  return {0.5 * (a + b), out, Eigen::Vector2d(-out.y(), out.x())};
}

// The face's offset along `out` from the boundary [m]: the median of the nearby points'
// offsets within a cell of it, twice (from the boundary, then from the first estimate), so that
// the other face of a thin wall stays out. Empty with too few points.
std::optional<double> face_offset(const SemanticGrid& grid, const BandPointIndex& surface,
                                  const Eigen::Vector2i& wall, const Eigen::Vector2i& step,
                                  const Boundary& b) {
  const double res = grid.resolution;
  const Eigen::Vector2i across(-step.y(), step.x());
  std::vector<double> offsets;
  for (int k = -kFaceStretch; k <= kFaceStretch; ++k) {
    for (int row = -1; row <= 1; ++row) {
      const Eigen::Vector2i c = wall + k * across + row * step;
      if (!grid.contains(c)) continue;
      for (const Eigen::Vector2d& p : surface.in_cell(c)) offsets.push_back(b.out.dot(p - b.point));
    }
  }
  double face = 0;
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<double> near;
    for (const double s : offsets)
      if (std::fabs(s - face) <= res) near.push_back(s);
    if (near.size() < kMinFacePoints) return std::nullopt;
    face = quantile(near, 0.5);
  }
  return face;
}

// A wall cell or one no view saw (the inside of a wall, or behind it).
bool wall_or_unseen(const SemanticGrid& grid, const Eigen::Vector2i& c) {
  return grid.contains(c) &&
         (unobserved(grid, c) || grid.classes(c.x(), c.y()) == SemanticClass::wall);
}

// What a wall cell moved into the room (a step from `wall`) becomes: what the room holds in front
// of it, floor, or furniture two cells deep (a table or a cabinet against the wall stands up to its
// face; a speck of furniture in front of a face is the face's noise).
std::optional<SemanticClass> room_in_front(const SemanticGrid& grid, const Eigen::Vector2i& wall,
                                           const Eigen::Vector2i& step) {
  if (seen_as(grid, wall + step, SemanticClass::floor)) return SemanticClass::floor;
  if (seen_as(grid, wall + step, SemanticClass::furniture) &&
      seen_as(grid, wall + 2 * step, SemanticClass::furniture))
    return SemanticClass::furniture;
  return std::nullopt;
}

// One round of place_wall_faces in scan order, a layer of cells deep: the first round judges the
// cells whose front was floor or furniture before it (`round` 1), each later one only the cells
// behind a cell the round before moved, along that step. A bulge of noise in front of a face thus
// loses the same cells on every side of a room; in one round in scan order the cells moved had
// cascaded through a bulge where its outer cell came first and stopped at that cell elsewhere
// (rooms' top and left walls: far walls a cell or two thicker there on held-out survey seed 11).
int place_faces_round(SemanticGrid& grid, const BandPointIndex& walls,
                      const TraversabilityWeights& weights, Image<std::uint8_t>& furniture,
                      Image<std::uint8_t>& moved_in, int round) {
  const double res = grid.resolution;
  int moved = 0;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const Eigen::Vector2i c(col, row);
      if (!seen_as(grid, c, SemanticClass::wall)) continue;
      for (const Eigen::Vector2i& step : kFourNeighbours) {
        // Two cells of wall stay behind (a wall is thicker than a cell; one cell of it lets the
        // rooms leak diagonally), so the two faces of a thin wall never both move in. In scan
        // order: the first face judged wins.
        const int front_round =
            grid.contains(c + step) ? moved_in((c + step).x(), (c + step).y()) : 0;
        if (front_round != round - 1) continue;
        const std::optional<SemanticClass> room = room_in_front(grid, c, step);
        if (!room || !wall_or_unseen(grid, c - step) || !wall_or_unseen(grid, c - 2 * step))
          continue;
        const std::optional<double> face =
            face_offset(grid, walls, c, step, boundary_between(grid, c, c + step));
        if (!face || *face >= -0.5 * res) continue;  // the cell's centre is inside the wall
        grid.classes(col, row) = *room;
        grid.weight(col, row) = weights.of(*room);
        if (*room == SemanticClass::furniture) furniture(col, row) = 1;
        const Eigen::Vector2i behind = c - step;
        if (*face > -1.5 * res && unobserved(grid, behind)) {
          grid.classes(behind.x(), behind.y()) = SemanticClass::wall;
          grid.weight(behind.x(), behind.y()) = weights.of(SemanticClass::wall);
        }
        moved_in(col, row) = static_cast<std::uint8_t>(round);
        ++moved;
        break;
      }
    }
  }
  return moved;
}

}  // namespace

int place_wall_faces(SemanticGrid& grid, const BandPointIndex& walls,
                     const TraversabilityWeights& weights, Image<std::uint8_t>& furniture) {
  Image<std::uint8_t> moved_in(grid.width(), grid.height(), 0);  // the round a cell moved in
  int moved = 0;
  for (int round = 1; round <= kMaxFaceRounds; ++round) {
    const int layer = place_faces_round(grid, walls, weights, furniture, moved_in, round);
    if (layer == 0) break;
    moved += layer;
  }
  return moved;
}

int place_leaf_faces(SemanticGrid& grid, const BandPointIndex& doors,
                     const Image<std::uint8_t>& floor_seen, const TraversabilityWeights& weights,
                     Image<std::uint8_t>& leaf) {
  const double res = grid.resolution;
  const auto is_leaf = [&](const Eigen::Vector2i& c) {
    return grid.contains(c) && leaf(c.x(), c.y()) &&
           grid.classes(c.x(), c.y()) == SemanticClass::door;
  };
  int moved = 0;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const Eigen::Vector2i c(col, row);
      if (!is_leaf(c) || !floor_seen(col, row)) continue;
      for (const Eigen::Vector2i& step : kFourNeighbours) {
        // Across the leaf: two or three cells deep along the step (the third where the leaf's
        // points reach into its wall's face cell), the leaf running on beside c (its end, judged
        // along the leaf, would measure the end's points as a face and shorten it).
        const Eigen::Vector2i across(-step.y(), step.x());
        if (!seen_as(grid, c + step, SemanticClass::floor) || !is_leaf(c - step) ||
            is_leaf(c - 3 * step) || !(is_leaf(c + across) || is_leaf(c - across)))
          continue;
        const std::optional<double> face =
            face_offset(grid, doors, c, step, boundary_between(grid, c, c + step));
        if (!face || *face >= -0.5 * res) continue;  // the cell's centre is inside the leaf
        grid.classes(col, row) = SemanticClass::floor;
        grid.weight(col, row) = weights.of(SemanticClass::floor);
        leaf(col, row) = 0;
        ++moved;
        break;
      }
    }
  }
  return moved;
}

}  // namespace kartograf::semantic::detail
