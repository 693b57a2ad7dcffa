#pragma once
// The two threshold-sweep methods of the room segmentation survey (docs/methods.md M4 steps 1-2;
// R. Bormann et al., ICRA 2016), each followed by growing the rooms over the rest of the free
// space (grow_rooms).
//
// Morphological: the free space is eroded one cell at a time (3x3); after each erosion every
// separate region whose area lies within the limits becomes a room and leaves the map; at most
// max_erosions erosions. k erosions leave the cells farther than k from any other cell in the
// chessboard metric, so the sweep is a walk down the component tree of that distance: the first
// region on each branch whose area fits is a room.
//
// Distance transform: the free space is eroded once, its Euclidean distance transform rounded to
// whole cells (at most 255), and thresholded at every t from 255 down to 1; the threshold with the
// most regions whose area lies within the limits (ties: the lowest t) gives the room centres.
//
// Areas are cell counts times resolution^2 (the reference measures contour polygons, a few
// percent smaller).
#include <optional>

#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/rooms/furniture.hpp"
#include "kartograf/rooms/room_segmentation.hpp"

namespace kartograf::rooms {

// How the room centres are grown over the rest of the free space: the reference's wavefront
// (grow_rooms) or by falling clearance (grow_rooms_by_clearance: rooms meet at narrowings).
enum class RoomGrowth { wavefront, clearance };

struct MorphologicalParams {
  AreaLimits room_area{0.8, 47.0};  // m^2, the reference's evaluation settings
  int max_erosions = 73;
  RoomGrowth growth = RoomGrowth::clearance;
  // Segment without furniture (furniture.hpp); empty: the map as it is, like the reference.
  std::optional<FurnitureParams> furniture = FurnitureParams{};
};

struct DistanceTransformParams {
  AreaLimits room_area{0.35, 163.0};
  RoomGrowth growth = RoomGrowth::clearance;
  std::optional<FurnitureParams> furniture = FurnitureParams{};  // as MorphologicalParams
};

// Throw Error for a map without free cells, a resolution <= 0 or bad limits.
RoomSegmentation segment_morphological(const OccupancyGrid& map,
                                       const MorphologicalParams& params = {});
RoomSegmentation segment_distance_transform(const OccupancyGrid& map,
                                            const DistanceTransformParams& params = {});

}  // namespace kartograf::rooms
