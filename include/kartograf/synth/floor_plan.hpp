#pragma once
// The synthetic world's 2-D ground truth, on one grid: the occupancy map a robot would build
// (a horizontal slice: walls and furniture footprints occupied, rooms free, outside the building
// occupied as in the ipa room-segmentation maps), the ground-truth rooms (each room one
// 4-connected region; doorways closed, as the ipa ground truth does; the corridor is a room) and
// a semantic grid.
//
// Cells are classified at their centres for the building's structure (so that, with the layout on
// a 5 cm lattice and a 5 cm grid, every room has exactly its area in cells) and by any overlap for
// furniture and door leaves (so that thin ones are not lost).
#include <string>
#include <vector>

#include "kartograf/core/label_image.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/core/semantic_class.hpp"
#include "kartograf/synth/world.hpp"

namespace kartograf::synth {

struct RoomRecord {
  Label id = 0;
  std::string name;
  RoomKind kind = RoomKind::room;
  Rect2 rect;       // interior [m]
  double area = 0;  // m^2 (rect)
  int cells = 0;    // cells labelled with this room
};

struct FloorPlan {
  OccupancyGrid grid;  // ROS convention (row 0 = largest y)
  LabelImage rooms;    // room id per cell, 0 = wall, doorway, outside; same indexing as grid
  // floor (free room cells), wall, door (doorway openings and door leaves), furniture; unknown
  // outside the building.
  SemanticImage semantic;
  std::vector<RoomRecord> room_records;
};

struct FloorPlanParams {
  double resolution = 0.05;  // metres per cell
  double margin = 0.5;       // metres of outside around the building
  bool furniture = true;     // false: the plain map (no furniture, no door leaves)
};

FloorPlan make_floor_plan(const World& world, const FloorPlanParams& options = {});

}  // namespace kartograf::synth
