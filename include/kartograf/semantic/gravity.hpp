#pragma once
// Gravity ("up") estimated from the data (docs/methods.md M2 step 3), not assumed from the sensor's
// mounting, so that it works for RGB-D frames (camera y roughly down) and for laser scans in any
// frame.
//
// Method:
//  1. Axis. Every large region (area >= min_region_area) proposes its plane normal (PCA of its
//     points: per-pixel normals are biased by smoothing at edges) as an axis. An
//     axis scores the area of all large regions whose normal is within axis_tolerance_deg of it or
//     of its opposite (floor and ceiling, table tops: horizontal surfaces are few large parallel
//     planes, while walls split over two or more directions). With a prior (an RGB-D camera: up is
//     roughly -y), only axes within prior_tolerance_deg of the prior's line are candidates. The
//     best axis is refined as the area-weighted mean of its supporting normals (signs aligned).
//     Axes whose farthest planes (step 2) make no plausible room around the sensor (floor more
//     than max_sensor_height below, ceiling more than max_ceiling_height above) rank after all
//     plausible ones: large walls (a corridor, a scanner that sees little ceiling) then lose.
//  2. Sign. Normals face the sensor, so the supporting regions facing +axis lie below the sensor
//     and those facing -axis above it. With a prior its sign decides. Otherwise the floor is taken
//     to be the nearer of the two extreme planes, the farthest on each side (a robot's or tripod's
//     sensor sits below half the room height). When all face one way (a scanner that sees only
//     the ceiling, a camera that sees only the floor), they are the floor if the farthest is within
//     max_sensor_height of the sensor, else the ceiling.
//  3. Floor = the lowest large horizontal region facing up, ceiling = the highest large horizontal
//     region facing down (heights p . up, relative to the sensor), the floor below the sensor
//     (height < 0) and the ceiling above it; either may be absent from view.
#include <optional>
#include <span>

#include <Eigen/Core>

#include "kartograf/semantic/regions.hpp"

namespace kartograf::semantic {

struct GravityParams {
  double min_region_area = 0.3;  // m^2: regions that vote and can be floor or ceiling
  double axis_tolerance_deg = 10.0;
  std::optional<Eigen::Vector3d> prior_up;  // e.g. (0, -1, 0) for a camera looking ahead
  double prior_tolerance_deg = 45.0;
  // Without a prior and with planes on one side only: farther than this from the sensor they are a
  // ceiling, not a floor (sensors on robots and tripods sit lower).
  double max_sensor_height = 2.0;  // m
  // Axes that put the floor farther than max_sensor_height below the sensor or the ceiling
  // farther than this above it lose to any axis that does not (a wall is no floor or ceiling).
  double max_ceiling_height = 6.0;  // m
  // Up known from elsewhere (a map's gravity through the view's pose; the points' frame): the
  // view is labelled with it instead of estimating it, so a view without floor or ceiling in
  // sight still is. known_floor_height (p . up of the floor) stands in when it sees no floor.
  std::optional<Eigen::Vector3d> known_up;
  std::optional<double> known_floor_height;
};

struct GravityEstimate {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // unit, in the points' frame
  double support_area = 0;                        // m^2 of regions parallel to up
  std::optional<double> floor_height;             // p . up of the floor (mean over its region)
  std::optional<double> ceiling_height;
};

// `regions` measured with any `up` (only plane normals, areas and centroids are used here; measure
// again with the estimated up for heights and widths). Throws Error when no large region votes.
GravityEstimate estimate_gravity(std::span<const RegionMeasurements> regions,
                                 const GravityParams& params = {});

// Floor and ceiling heights for a known up (step 3 alone), on regions measured with that up.
void find_floor_and_ceiling(std::span<const RegionMeasurements> regions,
                            const GravityParams& params, GravityEstimate& estimate);

}  // namespace kartograf::semantic
