#pragma once
// Furniture found in the semantic grid's cells rather than in the views (a step of
// build_semantic_grid).
#include <cstdint>

#include "kartograf/semantic/semantic_grid.hpp"

namespace kartograf::semantic::detail {

// A cabinet or shelf against a wall, whose front the views took for a wall: a piece of wall cells
// of furniture size (at most `max_extent` long, `max_area` in hull), most of them next to floor,
// that stands in front of a longer wall with only unseen cells between them (rows or columns of
// more than `min_depth_cells`, a wall's inside, and at most `max_depth_cells`: the pocket its top
// and sides hid) and no door beside them. The front and the pocket become furniture (`furniture`
// marks them, weight `weight`). Returns the number of fronts.
int fronts_against_walls(SemanticGrid& grid, double max_extent, double max_area,
                         int min_depth_cells, int max_depth_cells, float weight,
                         Image<std::uint8_t>& furniture);

}  // namespace kartograf::semantic::detail
