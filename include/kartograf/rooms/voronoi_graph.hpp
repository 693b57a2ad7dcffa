#pragma once
// The generalised Voronoi graph of a map's free space and its critical lines
// (docs/methods.md M4 step 3; R. Bormann et al., "Room Segmentation: Survey, Implementation, and
// Analysis", ICRA 2016, and ipa_room_segmentation's VoronoiSegmentation). Shared by the Voronoi
// segmentation and the Voronoi random field method.
//
// 1. Clearance: the exact Euclidean distance of every free cell to the nearest cell that is not
//    free (cells outside the map count as obstacles), with that nearest obstacle cell.
// 2. Graph: the medial axis of the free space, made thin and connected: cells whose neighbours'
//    nearest obstacles lie far apart (more than feature_separation x clearance) anchor it, and a
//    homotopic thinning ordered by clearance joins the anchors along the ridges of the clearance.
//    As in the reference, the graph lives only in the free space opened by a 3x3 square and then
//    eroded twice more (it keeps off walls and clutter; on maps at reference_resolution, the
//    reference's 0.05 m; the counts scale with the cells' size), and every leaf branch is
//    collapsed into the node it starts from (one level: branch points of the unpruned graph are
//    kept).
// 3. Critical points (as the reference): the graph is cut into stretches, each grown breadth first
//    along the graph from the first unvisited graph cell in raster order over unvisited cells until
//    it holds more than neighbourhood_index / clearance cells or max_iterations steps were taken
//    (small clearance, e.g. a door: a long stretch; open space: a short one); each stretch gives
//    its cell of least clearance (ties: the first in raster order). With stretch_minima = false,
//    the critical points are instead the graph cells of >= 2 graph neighbours whose clearance is
//    the least of such a neighbourhood around themselves (strict local minima; fewer lines).
// 4. Critical lines join a critical point to its nearest obstacle cell and to the nearest obstacle
//    cell farther than the clearance from that one. Lines whose two halves meet at an angle below
//    min_angle_deg (room corners) are dropped, and of two critical points closer than
//    min_critical_point_distance_factor x clearance only the one with the wider angle (ties: the
//    shorter line) is kept.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/image.hpp"
#include "kartograf/core/occupancy_grid.hpp"

namespace kartograf::rooms {

struct VoronoiGraphParams {
  int neighbourhood_index = 280;                    // the reference's voronoi_neighborhood_index
  int max_iterations = 150;                         // the reference's max_iterations
  double min_critical_point_distance_factor = 0.5;  // the reference's evaluation setting
  double min_angle_deg = 0.0;                       // 0: keep every angle (the reference)
  double feature_separation = 1.0;  // anchor: nearest obstacles > this x clearance apart
  bool stretch_minima = true;  // false: strict local minima instead of the reference's stretches
  // neighbourhood_index and max_iterations count cells of maps at this resolution (m/cell; the
  // reference's 0.05 m maps). On another map they are scaled so that a stretch covers the same
  // metres: max_iterations (steps along the graph) by reference / resolution, and
  // neighbourhood_index (cells x clearance in cells) by its square.
  double reference_resolution = 0.05;
};

struct CriticalLine {
  Eigen::Vector2i point = Eigen::Vector2i::Zero();    // critical point (column, row)
  Eigen::Vector2i basis_a = Eigen::Vector2i::Zero();  // its nearest obstacle cell
  Eigen::Vector2i basis_b = Eigen::Vector2i::Zero();  // the second one (other side)
  double clearance = 0.0;                             // cells
  double angle_deg = 0.0;                             // between point->basis_a and point->basis_b
  double length = 0.0;                                // |point-basis_a| + |point-basis_b|, cells
};

struct VoronoiGraph {
  Image<float> clearance;                // cells; 0 on cells that are not free
  Image<std::uint8_t> graph;             // 1: pruned Voronoi graph cell
  std::vector<CriticalLine> candidates;  // every critical point, before the angle/spacing filter
  std::vector<CriticalLine> critical_lines;  // those kept
};

// A count of cells or graph steps set for maps of `reference_resolution`, on a map of
// `resolution` (both m/cell): count x (reference / resolution)^power, rounded, at least 1 (power 2
// for a count that measures an area).
int cells_at_resolution(double count, double reference_resolution, double resolution,
                        int power = 1);

// Throws Error naming the input for an empty map, one without free cells or bad parameters.
VoronoiGraph build_voronoi_graph(const OccupancyGrid& map, const VoronoiGraphParams& params = {});

// Nearest obstacle cell of every cell (itself for non-free cells) and its Euclidean distance;
// cells outside the map are obstacles. Exact (lower envelope of parabolas, two passes).
struct NearestObstacles {
  Image<float> clearance;
  Image<Eigen::Vector2i> nearest;
};
NearestObstacles nearest_obstacles(const Image<std::uint8_t>& free_cells);

}  // namespace kartograf::rooms
