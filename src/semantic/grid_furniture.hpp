#pragma once
// Furniture found in the semantic grid's cells rather than in the views (a step of
// build_semantic_grid).
#include <cstdint>

#include "kartograf/semantic/semantic_grid.hpp"

namespace kartograf::semantic::detail {

// What a front rule found: the fronts, and the cells of their pockets made wall.
struct FrontsFound {
  int fronts = 0;
  int wall_inside_cells = 0;
};

// A cabinet or shelf against a wall, whose front the views took for a wall: a piece of wall cells
// of furniture size (at most `max_extent` long, `max_area` in hull), most of them next to floor,
// holding no wall between two rooms (seen floor just beyond both sides of a few cells across),
// that stands in front of a longer wall with only unseen cells between them (rows or columns of
// more than `min_depth_cells`, a wall's inside, and at most `max_depth_cells`, with floor within
// 3 cells beyond one end: the pocket its top and sides hid, behind a face the room saw) and no
// door beside them. The front and the pocket become furniture (`furniture` marks them), but for
// the pocket's cells within `inside_cells` of a longer wall whose far side the next room saw
// (floor within 2 cells beyond it; the line running on 0.4 m either way): the inside of the wall
// the cabinet stands against, whose near face it hid, which become wall.
FrontsFound fronts_against_walls(SemanticGrid& grid, double max_extent, double max_area,
                                 int min_depth_cells, int inside_cells, int max_depth_cells,
                                 const TraversabilityWeights& weights,
                                 Image<std::uint8_t>& furniture);

// A cabinet against a wall whose front and sides the views took for walls, joined to the wall
// behind it: a furniture-sized pocket of unseen cells (rows or columns of at least two cells
// between wall cells, at most `max_depth_cells`), no door beside it, whose box has exactly one side
// that runs on as a wall past both corners (the wall behind; a wall's inside between two faces has
// two such sides) and floor beyond the opposite side (the front faces the room). The pocket (but
// for the wall's inside towards the back, as above) and the wall cells around it up to two cells
// out, but for the back's line, become furniture. Runs after fronts_against_walls and the walls'
// insides.
FrontsFound joined_fronts_against_walls(SemanticGrid& grid, double max_extent, double max_area,
                                        int inside_cells, int max_depth_cells,
                                        const TraversabilityWeights& weights,
                                        Image<std::uint8_t>& furniture);

// The unseen cells behind furniture: row and column runs of at most `max_depth_cells` unseen cells
// from a furniture cell with seen floor within 3 cells in front of it (a face the room saw) to a
// wall or furniture cell (a cabinet's top and back that its front hid), in furniture-sized pieces
// with no door beside them, become furniture. A wall end with floor within 2 cells behind it ends
// no run: it is the far face of a wall whose near face the furniture hid. Returns the pieces
// filled.
int pockets_behind_furniture(SemanticGrid& grid, double max_extent, double max_area,
                             int max_depth_cells, float weight, Image<std::uint8_t>& furniture);

// Furniture specks in walls: pieces (8-neighbours) of seen furniture cells with no seen floor
// around them that lie inside a wall's line (at most `max_cells` cells, closed by wall at both ends
// of every row or of every column) or on a wall's face as a thin layer along it (at most two cells
// thick, twice as long as thick). Furniture stands in a room, where the views that saw it saw the
// floor in front of it; such specks are wall points the views took for an object, or the depth
// noise behind a face, and they would stop the walls' insides and hidden backs from filling across
// them. They become wall (weight `weight`; `furniture` unmarks them). Returns the specks.
int furniture_specks_in_walls(SemanticGrid& grid, int max_cells, float weight,
                              Image<std::uint8_t>& furniture);

// The unseen cells on row and column runs of more than `min_cells` and at most `max_cells` unseen
// cells between two wall cells of which one belongs to a piece that may be a cabinet's front
// (furniture sized, most of it facing floor): what the walls' insides fill must leave to
// fronts_against_walls when the walls are thinner than the run.
Image<std::uint8_t> front_pockets(const SemanticGrid& grid, double max_extent, double max_area,
                                  int min_cells, int max_cells);

}  // namespace kartograf::semantic::detail
