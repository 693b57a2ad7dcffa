#pragma once
// The semantic grid's walls as solids (steps of build_semantic_grid): the cell lattice placed so
// that wall faces fall on cell boundaries, each wall cell's run direction, and walls seen from
// one side only given the thickness of those seen from both.
#include <span>

#include <Eigen/Core>

#include "kartograf/semantic/semantic_grid.hpp"

namespace kartograf::semantic::detail {

// Per axis, the offset of the cell boundaries that puts the wall faces on them, and what it rests
// on. Faces are 0.25 m patches of the band's wall points that lie along the other axis;
// `crispness` is how tightly each one's points keep to its own offset, modulo the resolution
// (exp(-(2 pi sigma / resolution)^2 / 2) for a Gaussian spread sigma across the face; 0 without
// faces). `offset`, in [0, resolution), is the circular mean of all the band's wall points (faces
// along the axis spread uniformly and cancel): the best one lattice for the faces, however well
// they agree (the default lattice serves unrelated faces no better). 0 on an axis whose faces are
// less crisp than `min_crispness`: points spread over both cells at a face are read better off a
// lattice that does not cut them at their face.
struct FacePhase {
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
  Eigen::Vector2d crispness = Eigen::Vector2d::Zero();
};
FacePhase wall_face_phase(std::span<const Eigen::Vector3d> points,
                          std::span<const SemanticClass> labels, double floor_z,
                          const SemanticGridParams& options, double min_crispness);

// Direction bin (8 bins over 180 degrees, bin b at angle b * pi / 8 in cell coordinates) of each
// wall cell: the direction of the longest run of wall cells through it, when that run is at least
// twice as long as the run across it; -1 where no direction dominates (corners, specks). Runs, not
// a local covariance, so that thick and noisy wall bands still read as lines.
Image<int> wall_direction_bins(const Image<SemanticClass>& classes);

// The thickness, in cells, of the walls seen from both sides (floor or furniture on both faces;
// runs of 2 to max_cells cells): the k whose runs of k and k + 1 cells are the most (a wall k
// cells thick covers either, by where its faces fall); 0 where fewer than `min_samples` runs
// measure one. With `through_unseen`, a run goes on through the cells no view saw (the inside of
// a wall seen from both sides, before it is filled).
int two_sided_wall_thickness(const SemanticGrid& grid, int max_cells, int min_samples,
                             bool through_unseen = false);

// Walls seen from one side (floor or furniture in front, nothing seen behind: a building's outer
// walls, a wall of a room no view entered) are extended into the unseen cells behind them to
// `thickness` cells (nothing changes for 0).
void back_one_sided_walls(SemanticGrid& grid, int thickness, int max_cells, float weight);

// The hidden blocks where two walls meet at a corner, which no room sees: an unseen cell with wall
// running on for at least 3 cells along its row one way and along its column one way is wall;
// repeated until a block `thickness` cells square is filled (nothing changes for 0).
void fill_wall_corners(SemanticGrid& grid, int thickness, float weight);

// A wall line hidden behind furniture: along a row or a column, a gap of at most `max_gap_cells`
// unseen or furniture cells, with furniture within `beyond_cells` across it, between two wall
// cells from which the wall runs on for at least `beyond_cells` each way (more than a wall is
// thick, so that the line is a wall's length, not another wall's thickness), or, at the far end,
// across the line both ways in one of its first `beyond_cells` rows (the wall the line meets: a
// T), is wall: its unseen
// cells, and its furniture cells (the wall's face seen above the furniture, which the views left
// unlabelled in a region the furniture cut small, or the furniture's back in the noise of the face:
// furniture stands in front of a wall, not in its line); `furniture` unmarks those. Returns the
// furniture cells made wall.
// A room's corner hidden behind furniture: from a wall cell whose wall runs on for `beyond_cells`
// behind it, along its row or column through unseen or furniture cells, then across through such
// cells, to a wall cell whose wall runs on for `beyond_cells` beyond it (the perpendicular wall),
// both legs at most `max_gap_cells` long, with furniture within `beyond_cells` across either leg:
// the legs' cells become wall (weight `weight`). The two outer walls of a corner that a cabinet
// hid end at its sides; the wall-line rule needs wall at both ends of a straight gap. Returns the
// cells made wall. Runs after wall_lines_behind_furniture.
int wall_corners_behind_furniture(SemanticGrid& grid, int max_gap_cells, int beyond_cells,
                                  float weight);

int wall_lines_behind_furniture(SemanticGrid& grid, int max_gap_cells, int beyond_cells,
                                float weight, Image<std::uint8_t>& furniture);

// A wall line no view looked along: from a wall cell whose wall runs on for `beyond_cells` behind
// it, along its row or column through at most `max_gap_cells` cells that no view saw or that hold
// an obstacle the views could not name, to a wall cell (the line's far piece, or the wall it
// meets at a corner), when at most half of those cells lie beside a wall cell across the line (a
// wall's own thickness or outside). Those cells become wall (weight `weight`): walls run on
// between their seen pieces, where a doorway would have shown floor. Returns the cells made wall.
int wall_lines_across_unseen(SemanticGrid& grid, int max_gap_cells, int beyond_cells, float weight);

}  // namespace kartograf::semantic::detail
