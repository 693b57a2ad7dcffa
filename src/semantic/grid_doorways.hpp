#pragma once
// The semantic grid's doorways found as gaps in its walls (a step of build_semantic_grid), apart
// from the cell classification: they are measured on the wall points, finer than the cells.
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "kartograf/semantic/semantic_grid.hpp"
#include "semantic/grid_band_points.hpp"

namespace kartograf::semantic::detail {

// Appends an object of `cells` to the grid, described from its cells, and returns it.
using AddObject = std::function<SemanticObject&(ObjectKind, SemanticClass, const std::string&,
                                                std::vector<Eigen::Vector2i>)>;

// Doorways as gaps of door width in a wall line (the walls `wall_ids`), with observed floor along
// the gap and no obstacle across its middle. The two faces of a wall give one gap each; gaps whose
// centres are closer than half the smallest door width merge. Each doorway's cells become door
// cells; its opening is measured on the wall points in the height band (`walls`) where enough
// are there.
void add_gap_doorways(SemanticGrid& grid, const SemanticGridParams& options,
                      const BandPointIndex& walls, const std::vector<int>& wall_ids,
                      const AddObject& add_object);

}  // namespace kartograf::semantic::detail
