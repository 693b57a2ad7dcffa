#pragma once
// The Voronoi graph room segmentation of the survey (docs/methods.md M4 step 3; R. Bormann et al.,
// ICRA 2016; ipa_room_segmentation's VoronoiSegmentation):
// 1. the pruned generalised Voronoi graph of the free space and its critical lines
//    (voronoi_graph.hpp);
// 2. the critical lines (one cell wide, 8-connected) cut the free space into cells, its
//    4-connected parts; parts whose area lies within room_area become cells, the rest (and the
//    lines) join the cells by growing them (grow_rooms);
// 3. the cells merge by the five heuristics of voronoi_merging.hpp.
// Areas are cell counts times resolution^2 (the reference measures contour polygons).
#include <optional>

#include "kartograf/core/label_image.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/rooms/furniture.hpp"
#include "kartograf/rooms/room_segmentation.hpp"
#include "kartograf/rooms/voronoi_graph.hpp"
#include "kartograf/rooms/voronoi_merging.hpp"

namespace kartograf::rooms {

struct VoronoiParams {
  VoronoiGraphParams graph;
  CellMergeParams merging;
  // The reference's evaluation setting (room_area_factor_*_limit_voronoi 0.1 .. 1e6; its params
  // yaml lists 1.53 .. 120, commented out there in favour of these).
  AreaLimits room_area{0.1, 1e6};
  // Segment without furniture (furniture.hpp); empty: the map as it is, like the reference.
  std::optional<FurnitureParams> furniture = FurnitureParams{};
};

// Throws Error for a map without free cells, a resolution <= 0 or bad parameters.
RoomSegmentation segment_voronoi(const OccupancyGrid& map, const VoronoiParams& params = {});

// Step 2 alone: the cells cut out by the graph's critical lines, grown over the free space and
// labelled 1..n, before any merging.
LabelImage voronoi_cells(const OccupancyGrid& map, const VoronoiGraph& graph, const AreaLimits& room_area);

}  // namespace kartograf::rooms
