#include "kartograf/synth/floor_plan.hpp"

#include <algorithm>
#include <cmath>

#include "kartograf/core/error.hpp"

namespace kartograf::synth {

namespace {

// Cells whose square overlaps `r` (positive area), as an inclusive column / row range.
struct CellRange {
  int col0, col1, row0, row1;
};

CellRange overlapped_cells(const OccupancyGrid& grid, const Rect2& r) {
  const double res = grid.resolution;
  const Eigen::Vector2d o = grid.origin.head<2>();
  const int col0 = static_cast<int>(std::floor((r.min.x() - o.x()) / res + 1e-9));
  const int col1 = static_cast<int>(std::ceil((r.max.x() - o.x()) / res - 1e-9)) - 1;
  const int y0 = static_cast<int>(std::floor((r.min.y() - o.y()) / res + 1e-9));
  const int y1 = static_cast<int>(std::ceil((r.max.y() - o.y()) / res - 1e-9)) - 1;
  // Row 0 is the top (largest y).
  return {std::max(col0, 0), std::min(col1, grid.width() - 1), std::max(grid.height() - 1 - y1, 0),
          std::min(grid.height() - 1 - y0, grid.height() - 1)};
}

}  // namespace

FloorPlan make_floor_plan(const World& world, const FloorPlanParams& options) {
  require(options.resolution > 0 && options.resolution <= 1,
          "make_floor_plan: resolution must be in (0, 1] m");
  require(options.margin >= 0, "make_floor_plan: margin must be >= 0");
  const double res = options.resolution;
  const Eigen::Vector2d lo = world.bounds.min - Eigen::Vector2d::Constant(options.margin);
  const Eigen::Vector2d hi = world.bounds.max + Eigen::Vector2d::Constant(options.margin);
  const Eigen::Vector2d origin_cells = (lo / res).array().floor();
  const Eigen::Vector2d end_cells = (hi / res).array().ceil();
  const int width = static_cast<int>(end_cells.x() - origin_cells.x());
  const int height = static_cast<int>(end_cells.y() - origin_cells.y());

  FloorPlan plan;
  plan.grid.resolution = res;
  // cells / 20 rather than cells * 0.05 for a 1/n resolution: the decimal value exactly rounded.
  const double per_metre = std::round(1.0 / res);
  const bool decimal = std::fabs(per_metre * res - 1.0) < 1e-12;
  auto to_metres = [&](double cells) { return decimal ? cells / per_metre : cells * res; };
  plan.grid.origin = Eigen::Vector3d(to_metres(origin_cells.x()), to_metres(origin_cells.y()), 0.0);
  plan.grid.cells = Image<CellState>(width, height, CellState::occupied);
  plan.rooms = LabelImage(width, height, kUnlabeled);
  plan.semantic = SemanticImage(width, height, SemanticClass::unknown);

  // Wall rings: within a wall thickness of a room (closed rectangles).
  std::vector<Rect2> rings;
  for (const Room& room : world.rooms)
    rings.push_back(room.rect.expanded(world.wall_thickness + 1e-9));

  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      const Eigen::Vector2d c = plan.grid.cell_center(col, row);
      CellState state = CellState::occupied;
      SemanticClass semantic = SemanticClass::unknown;
      if (const Label r = world.room_at(c)) {
        state = CellState::free;
        semantic = SemanticClass::floor;
        plan.rooms(col, row) = r;
      } else if (world.doorway_at(c) >= 0) {
        state = CellState::free;
        semantic = SemanticClass::door;
      } else if (std::any_of(rings.begin(), rings.end(),
                             [&](const Rect2& ring) { return ring.contains(c); })) {
        semantic = SemanticClass::wall;
      }
      plan.grid.cells(col, row) = state;
      plan.semantic(col, row) = semantic;
    }
  }

  if (options.furniture) {
    auto mark = [&](const Rect2& footprint, SemanticClass semantic) {
      const CellRange range = overlapped_cells(plan.grid, footprint);
      for (int row = range.row0; row <= range.row1; ++row) {
        for (int col = range.col0; col <= range.col1; ++col) {
          plan.grid.cells(col, row) = CellState::occupied;
          plan.semantic(col, row) = semantic;
        }
      }
    };
    for (const Furniture& item : world.furniture) mark(item.footprint, SemanticClass::furniture);
    for (const DoorLeaf& leaf : world.door_leaves) {
      mark(world.solids[leaf.solid].box.footprint(), SemanticClass::door);
    }
  }

  for (const Room& room : world.rooms) {
    RoomRecord record{room.id, room.name, room.kind, room.rect, room.rect.area(), 0};
    plan.room_records.push_back(record);
  }
  for (const Label id : plan.rooms.pixels()) {
    if (id) ++plan.room_records[id - 1].cells;
  }
  return plan;
}

}  // namespace kartograf::synth
