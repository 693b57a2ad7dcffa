// The floor plan's ground truth: rooms are single 4-connected regions with their exact areas,
// doorways are closed in the room labels but free in the map, furniture is occupied.
#include <gtest/gtest.h>

#include <queue>

#include "kartograf/core/error.hpp"
#include "kartograf/synth/floor_plan.hpp"

namespace kartograf::synth {
namespace {

// Number of 4-connected regions of cells labelled `id`.
int regions(const LabelImage& labels, Label id) {
  Image<std::uint8_t> seen(labels.width(), labels.height(), 0);
  int count = 0;
  for (int y = 0; y < labels.height(); ++y) {
    for (int x = 0; x < labels.width(); ++x) {
      if (labels(x, y) != id || seen(x, y)) continue;
      ++count;
      std::queue<std::pair<int, int>> queue;
      queue.push({x, y});
      seen(x, y) = 1;
      while (!queue.empty()) {
        const auto [cx, cy] = queue.front();
        queue.pop();
        for (auto [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
          const int nx = cx + dx, ny = cy + dy;
          if (nx < 0 || ny < 0 || nx >= labels.width() || ny >= labels.height()) continue;
          if (labels(nx, ny) == id && !seen(nx, ny)) seen(nx, ny) = 1, queue.push({nx, ny});
        }
      }
    }
  }
  return count;
}

TEST(SynthFloorPlan, RoomsAreSingleRegionsWithTheirAreas) {
  for (std::uint64_t seed : {1, 2, 3, 4}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const World w = make_building(seed);
    const FloorPlan plan = make_floor_plan(w);
    ASSERT_EQ(plan.room_records.size(), w.rooms.size());
    const double cell_area = plan.grid.resolution * plan.grid.resolution;
    for (const RoomRecord& r : plan.room_records) {
      EXPECT_EQ(regions(plan.rooms, r.id), 1) << r.name;
      // The layout lies on the 5 cm lattice: exact, up to rounding of the area itself.
      EXPECT_NEAR(r.cells, r.area / cell_area, 0.5) << r.name;
    }
    // Different rooms never touch (doorways and walls separate them).
    for (int y = 0; y + 1 < plan.rooms.height(); ++y) {
      for (int x = 0; x + 1 < plan.rooms.width(); ++x) {
        const Label a = plan.rooms(x, y), b = plan.rooms(x + 1, y), c = plan.rooms(x, y + 1);
        if (a && b) {
          EXPECT_EQ(a, b);
        }
        if (a && c) {
          EXPECT_EQ(a, c);
        }
      }
    }
  }
}

TEST(SynthFloorPlan, CellsFollowTheWorld) {
  const World w = make_building(6);
  const FloorPlan plan = make_floor_plan(w);
  const FloorPlan plain = make_floor_plan(w, {0.05, 0.5, false});
  const OccupancyGrid& g = plan.grid;
  int door_cells = 0;
  for (int row = 0; row < g.height(); ++row) {
    for (int col = 0; col < g.width(); ++col) {
      const Eigen::Vector2d c = g.cell_center(col, row);
      const Label room = w.room_at(c);
      EXPECT_EQ(plan.rooms(col, row), room);
      if (room) {
        EXPECT_TRUE(w.room(room).rect.contains(c));
      }
      const bool doorway = w.doorway_at(c) >= 0;
      door_cells += doorway && plain.semantic(col, row) == SemanticClass::door ? 1 : 0;
      // Without furniture: free exactly in rooms and doorways; outside is occupied (ipa maps).
      EXPECT_EQ(plain.grid.cells(col, row) == CellState::free, room != 0 || doorway);
      EXPECT_NE(plain.grid.cells(col, row), CellState::unknown);
      if (!room && !doorway) {
        EXPECT_TRUE(plain.semantic(col, row) == SemanticClass::wall ||
                    plain.semantic(col, row) == SemanticClass::unknown);
      }
    }
  }
  double doorway_area = 0;
  for (const Doorway& d : w.doorways) doorway_area += d.opening.area();
  EXPECT_NEAR(door_cells, doorway_area / 0.0025, 0.5);
  // Furniture footprints are occupied, and in the semantic grid furniture.
  for (const Furniture& f : w.furniture) {
    const Eigen::Vector2i cell = g.cell_of(f.footprint.center());
    EXPECT_EQ(g.cells(cell.x(), cell.y()), CellState::occupied);
    EXPECT_EQ(plan.semantic(cell.x(), cell.y()), SemanticClass::furniture);
    EXPECT_EQ(plan.rooms(cell.x(), cell.y()), f.room);  // ground-truth rooms include furniture
  }
  // Door leaves (4 cm) are not lost between cell centres.
  for (const DoorLeaf& leaf : w.door_leaves) {
    const Eigen::Vector2i cell = g.cell_of(w.solids[leaf.solid].box.footprint().center());
    EXPECT_EQ(plan.semantic(cell.x(), cell.y()), SemanticClass::door);
  }
  EXPECT_THROW(make_floor_plan(w, {0.0, 0.5, true}), Error);
}

}  // namespace
}  // namespace kartograf::synth
