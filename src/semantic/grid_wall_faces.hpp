#pragma once
// The semantic grid's wall faces placed from the wall points, and door leaves' faces from the door
// points (steps of build_semantic_grid): the depth noise spreads a face's points over both cells
// beside it, so a cell's own points cannot say on which side of it the face lies; the points along
// a stretch of the face can.
#include <cstdint>

#include "kartograf/core/image.hpp"
#include "kartograf/semantic/semantic_grid.hpp"
#include "semantic/grid_band_points.hpp"

namespace kartograf::semantic::detail {

// Each wall cell beside a floor cell (or furniture two cells deep) is judged on the face between
// them, measured as the median offset of the wall points along kFaceStretch cells of it: a cell
// whose centre lies on the room's side of the face holds less wall than room and becomes what the
// room holds there, floor or furniture (marked in `furniture`), and an unseen cell behind it whose
// centre the wall then covers becomes wall. Whether floor was seen in the cell itself does not
// matter: the floor before a face seen from afar is lost at grazing angles, while the face's
// points spread over cells into the room. Two cells of wall (or unseen) stay behind every moved
// cell. The cells move a layer at a time (at most 4 layers): first those whose front was
// floor or furniture, then those behind a cell the layer before moved, so a bulge of noise in
// front of a face loses the same cells on every side of a room. Returns the number of wall cells
// moved.
int place_wall_faces(SemanticGrid& grid, const BandPointIndex& walls,
                     const TraversabilityWeights& weights, Image<std::uint8_t>& furniture);

// A door leaf (a few centimetres thick) whose room-side face lies near a cell boundary puts that
// face's points in the cells on both sides of it, and comes out two cells thick. Each leaf cell
// with seen floor in front of it, one or two more behind it and the leaf running on beside it is
// judged on the leaf's face as a wall cell is on the wall's: a cell whose centre lies on the room's
// side of the face becomes floor (and leaves `leaf`). The cell behind stays, so a leaf keeps a
// cell. Returns the cells moved.
int place_leaf_faces(SemanticGrid& grid, const BandPointIndex& doors,
                     const Image<std::uint8_t>& floor_seen, const TraversabilityWeights& weights,
                     Image<std::uint8_t>& leaf);

}  // namespace kartograf::semantic::detail
