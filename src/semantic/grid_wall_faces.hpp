#pragma once
// The semantic grid's wall faces placed from the wall points (a step of build_semantic_grid): the
// depth noise spreads a face's points over both cells beside it, so a cell's own points cannot
// say on which side of it the face lies; the points along a stretch of the face can.
#include <cstdint>

#include "kartograf/core/image.hpp"
#include "kartograf/semantic/semantic_grid.hpp"
#include "semantic/grid_wall_points.hpp"

namespace kartograf::semantic::detail {

// Each wall cell beside a floor cell (or furniture two cells deep) is judged on the face between
// them, measured as the median offset of the wall points along kFaceStretch cells of it: a cell
// whose centre lies on the room's side of the face holds less wall than room and becomes what the
// room holds there, floor or furniture (marked in `furniture`), where floor was seen (floor_seen),
// and an unseen cell behind it whose centre the wall then covers becomes wall. Two cells of wall
// (or unseen) stay behind every moved cell. One pass, in scan order: a bulge of noise two cells
// into the room is judged from its outer cell only. Returns the number of wall cells moved.
int place_wall_faces(SemanticGrid& grid, const WallPointIndex& walls,
                     const Image<std::uint8_t>& floor_seen, const TraversabilityWeights& weights,
                     Image<std::uint8_t>& furniture);

}  // namespace kartograf::semantic::detail
