#pragma once
// Cabinets standing against a wall that no view saw behind them (a step of build_semantic_grid).
#include <cstdint>

#include "kartograf/semantic/semantic_grid.hpp"

namespace kartograf::semantic::detail {

// How large a cabinet may be, in cells and m^2.
struct CabinetLimits {
  int max_extent_cells = 0;  // along its front
  int min_depth_cells = 0;   // from its front to the wall behind: deeper than a wall's inside
  int max_depth_cells = 0;
  double max_area = 0;
};

// A cabinet taller than the views look over, against a wall they never saw behind it: its front
// is a straight line of wall faces (within 2 cells across) facing floor, with a cell no view saw
// behind at most 2 wall cells, at most `max_extent_cells` long, whose line does not run on as a
// wall beyond its ends (a stretch of a longer wall is no front); beyond one of its ends the room
// runs on behind the front's plane to a wall line (its face seen, floor before it) deeper than
// `min_depth_cells` and at most `max_depth_cells` behind the front. Where most of the front's
// rows reach that depth through cells no view saw, furniture or unnamed obstacles only, the front
// and those cells become furniture (`furniture` marks them) and the line's unseen cells in those
// rows wall: the wall runs on behind the cabinet. Returns the cabinets.
int cabinets_before_hidden_walls(SemanticGrid& grid, const CabinetLimits& limits,
                                 const TraversabilityWeights& weights,
                                 Image<std::uint8_t>& furniture);

}  // namespace kartograf::semantic::detail
