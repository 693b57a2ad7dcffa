#pragma once
// Furniture in occupancy maps. Tables, chairs, bins and cupboards standing free in a room are
// small obstacles apart from the walls; every room segmentation method reads the gaps between
// them as doorways and splits rooms there (the survey's furnished maps lose 10-20 points of
// recall). Removing such obstacles before segmenting, and putting them back after, keeps the
// rooms whole; furniture standing against a wall stays part of the wall.
#include <optional>

#include "kartograf/core/occupancy_grid.hpp"

namespace kartograf::rooms {

struct FurnitureParams {
  double max_area_m2 = 1.0;   // an 8-connected obstacle region up to this area ...
  double max_extent_m = 2.0;  // ... whose bounding box diagonal is at most this is furniture
  // Furniture cells belong to the room they stand in (a room's extent and area include the
  // table's footprint, as the benchmark's ground truth draws rooms); false: no room, like walls.
  bool in_rooms = true;
};

// The cells whose labels a method keeps: the map's free cells, plus furniture cells when the
// furniture belongs to rooms. `work` is without_furniture(map) or the map itself.
const OccupancyGrid& room_cells(const OccupancyGrid& map, const OccupancyGrid& work,
                                const std::optional<FurnitureParams>& furniture);

// The map with every furniture region made free. Obstacles touching the map's border stay.
OccupancyGrid without_furniture(const OccupancyGrid& map, const FurnitureParams& params = {});

}  // namespace kartograf::rooms
