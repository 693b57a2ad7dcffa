#pragma once
// Path planning on the traversability weights of a semantic grid (method M2: "go to the door",
// "drive along the wall"): A* over 8-connected cells, where entering a cell of weight w costs
// step length / w (so doors at 0.7 are slower than floor) and weight 0 is impassable. Obstacles
// are inflated by the robot's radius; a diagonal step needs both cells beside it passable.
//
// Failures throw kartograf::Error: a start outside the map or in a blocked cell, and
// "goal unreachable: ..." when no passable path exists.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/color.hpp"
#include "kartograf/core/image.hpp"
#include "kartograf/semantic/semantic_grid.hpp"

namespace kartograf::semantic {

struct PlannerParams {
  double robot_radius = 0.20;      // cells whose centre is within this of an obstacle's are blocked
  float unobserved_weight = 0.0f;  // weight of unobserved cells (0: never drive into the unknown)

  void validate() const;  // throws Error naming the bad field
};

struct PlannedPath {
  std::vector<Eigen::Vector2i> cells;   // start .. goal, (col, row)
  std::vector<Eigen::Vector2d> points;  // their centres [m]
  double cost = 0;                      // sum of step / weight [m at weight 1]
  double length = 0;                    // [m]
  int target_object = 0;                // the object a query went to (0: none)
};

// The weights the planner uses: unobserved cells get unobserved_weight, then every cell within
// robot_radius of a weight-0 cell becomes 0.
Image<float> planning_weights(const SemanticGrid& grid, const PlannerParams& options = {});

// A* on a weight image (values in [0, 1], 0 impassable) with cells `resolution` metres apart.
// is_goal says which cells end the search; heuristic must not overestimate the remaining cost
// (e.g. metres to the goal / the largest weight). Throws Error for a blocked or outside start and
// "goal unreachable: <what>" when no goal cell can be reached.
PlannedPath plan_on_weights(const Image<float>& weights, double resolution,
                            const Eigen::Vector2i& start,
                            const std::function<bool(const Eigen::Vector2i&)>& is_goal,
                            const std::function<double(const Eigen::Vector2i&)>& heuristic,
                            const std::string& what);

// Point to point, on planning_weights(grid, options).
PlannedPath plan_path(const SemanticGrid& grid, const Eigen::Vector2d& start,
                      const Eigen::Vector2d& goal, const PlannerParams& options = {});

struct DoorQueryParams {
  double arrival_radius = 0.35;  // the path ends within this of the door's centre [m]
  bool doorways_only = true;     // openings, not door leaves standing against a wall
};
// "Go to the door": the cheapest path to any door object (the nearest reachable one); its id in
// target_object. Throws Error when the map has no door, "goal unreachable: ..." when none can be
// reached.
PlannedPath plan_to_nearest_door(const SemanticGrid& grid, const Eigen::Vector2d& start,
                                 const DoorQueryParams& query = {},
                                 const PlannerParams& options = {});

struct WallQueryParams {
  double offset = 0.5;        // metres from the wall line, on the robot's side
  double keep_weight = 0.25;  // cells off the offset line are this much slower at 1 m off it
  double arrival_radius = 0.3;
  double min_wall_length = 1.0;  // shorter wall objects (corner pieces) are not followed
};
// "Drive along the wall": from start to the far end of the nearest wall object (of at least
// min_wall_length), kept at `offset`
// from the wall's line (leaving it only around obstacles). The wall's id in target_object.
PlannedPath plan_along_nearest_wall(const SemanticGrid& grid, const Eigen::Vector2d& start,
                                    const WallQueryParams& query = {},
                                    const PlannerParams& options = {});

// The centre of the passable cell (after inflating by the robot radius) nearest to `point`
// within `max_distance` [m]: where a robot standing on unobserved ground (a scanner cannot see the
// floor beneath itself) starts planning. Empty when there is none.
std::optional<Eigen::Vector2d> nearest_passable_point(const SemanticGrid& grid,
                                                      const Eigen::Vector2d& point,
                                                      double max_distance,
                                                      const PlannerParams& options = {});

// Draws the path (cell centres joined by lines, a dot at each end) onto a picture made by
// render_map.
void draw_path(MapPicture& picture, const PlannedPath& path, const Rgb8& colour = {0, 110, 255});

}  // namespace kartograf::semantic
