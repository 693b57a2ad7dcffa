#pragma once
// The merging heuristics of the Voronoi segmentation (docs/methods.md M4 step 3; R. Bormann et al.,
// ICRA 2016, and ipa_room_segmentation's AbstractVoronoiSegmentation::mergeRooms, whose exact
// conditions these are).
//
// Each cell's perimeter is counted as in the reference: the cells outside it that touch it
// (8-neighbours, each counted once), split by what they belong to: a neighbouring cell or wall
// (anything not in a cell). The rules run one after the other; within a rule the cells are visited
// smallest first and after every merge the visit starts again (a merged cell joins its neighbour,
// which keeps its label):
// 1. area < max_area_m2, exactly one neighbour, wall <= 75 % of the perimeter: merge into it;
// 2. area < small_area_m2 and the neighbour sharing the most border holds > 20 % of the perimeter
//    (and has <= 80 % wall itself): merge into it;
// 3. one neighbour (or one holding > 98 % of the perimeter with the wall), > 50 % wall and that
//    neighbour > 15 % of the perimeter, the neighbour having <= 2 neighbours (or its two largest
//    borders >= 95 % of its perimeter): merge (two parts of one room);
// 3b. (not in the reference) a neighbour whose shared border is at least open_border_ratio x the
//    widest free space (2 x the largest clearance) of either cell: merge. The border spans both
//    cells, so no doorway lies between them: they are pieces of one corridor or hall, which the
//    graph cuts wherever its clearance is least along a stretch, and which rules 4 and 5 leave
//    apart once a piece's border is a small share of its long perimeter. A doorway off a corridor
//    is narrower than the room behind it (the room's width counts), so rooms stay apart. Also
//    merged: a neighbour whose shared border is at least open_end_ratio x the widest free space
//    of the narrower of the two cells, which opens onto the other across its whole width (the
//    piece of a corridor that meets a wider corner or hall).
// 4. a neighbour holding > 20 % of the perimeter (or > 10 % where the wall share lies within
//    [1 - 2r - 0.05, 1 - r] for that share r) while the cell holds > 10 % of the neighbour's:
//    merge (regions sharing most of their border); not in the reference: unless their shared
//    border is narrower than doorway_ratio x the widest free space of the narrower cell, a doorway
//    (rows of cubicles opening onto a narrow aisle no longer join across it);
// 5. the neighbour sharing the most border holds > 40 % of the perimeter: merge (clutter).
#include "kartograf/core/label_image.hpp"
#include "kartograf/core/occupancy_grid.hpp"

namespace kartograf::rooms {

struct CellMergeParams {
  double max_area_m2 = 12.5;  // rule 1 (the reference's max_area_for_merging)
  double one_neighbour_max_wall = 0.75;
  double small_area_m2 = 2.0;  // rule 2
  double small_min_shared = 0.2;
  double small_target_max_wall = 0.8;
  double part_min_wall = 0.5;  // rule 3
  double part_min_shared = 0.15;
  double part_dominant_share = 0.98;
  int part_target_max_neighbours = 2;
  double part_target_two_largest = 0.95;
  double shared_min = 0.2;  // rule 4
  double shared_min_low = 0.1;
  double shared_min_of_neighbour = 0.1;
  double dominant_neighbour = 0.4;  // rule 5
  double open_border_ratio = 0.88;  // rule 3b; 0: off (the reference)
  double open_end_ratio = 1.05;     // rule 3b, narrower cell; 0: off (the reference)
  double doorway_ratio = 0.95;      // rule 4's doorway test; 0: off (the reference)
};

// Merges the labelled cells (labels 1..n, 0 = none) of `cells` in place. Throws Error if the
// image differs from the map in size.
void merge_voronoi_cells(LabelImage& cells, const OccupancyGrid& map,
                         const CellMergeParams& params = {});

}  // namespace kartograf::rooms
