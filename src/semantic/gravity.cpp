#include "kartograf/semantic/gravity.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include "kartograf/core/error.hpp"

namespace kartograf::semantic {
namespace {

double cos_deg(double degrees) {
  return std::cos(degrees * std::numbers::pi / 180.0);
}

bool is_large(const RegionMeasurements& r, const GravityParams& params) {
  return r.area >= params.min_region_area;
}

// The farthest large plane on each side of an axis (normals along +axis: below the sensor if up
// is +axis), as distances from the sensor: the floor on one side, the ceiling on the other.
struct SideExtremes {
  std::optional<double> along, against;
};

SideExtremes side_extremes(std::span<const RegionMeasurements> regions, const Eigen::Vector3d& axis,
                           const GravityParams& params) {
  const double parallel_cos = cos_deg(params.axis_tolerance_deg);
  SideExtremes extremes;
  for (const RegionMeasurements& r : regions) {
    if (!is_large(r, params)) continue;
    const double along = r.plane_normal.dot(axis);
    if (std::fabs(along) < parallel_cos) continue;
    const double distance = std::fabs(r.centroid.dot(r.plane_normal));  // sensor to plane
    std::optional<double>& extreme = along > 0 ? extremes.along : extremes.against;
    extreme = std::max(extreme.value_or(0.0), distance);
  }
  return extremes;
}

// Whether the floor lies along +axis (up = +axis): the nearer of the two extremes is the floor;
// with one side in view, it is the floor when within max_sensor_height, else the ceiling.
bool floor_along(const SideExtremes& e, const GravityParams& params) {
  if (e.along && e.against) return *e.along <= *e.against;
  if (e.against) return *e.against > params.max_sensor_height;
  return e.along && *e.along <= params.max_sensor_height;
}

// A room around the sensor: the floor within max_sensor_height below, the ceiling within
// max_ceiling_height above (a wall axis puts "floor" or "ceiling" metres away).
bool plausible_room(const SideExtremes& e, const GravityParams& params) {
  const bool up_along = floor_along(e, params);
  const std::optional<double> floor = up_along ? e.along : e.against;
  const std::optional<double> ceiling = up_along ? e.against : e.along;
  return (!floor || *floor <= params.max_sensor_height) &&
         (!ceiling || *ceiling <= params.max_ceiling_height);
}

}  // namespace

void find_floor_and_ceiling(std::span<const RegionMeasurements> regions,
                            const GravityParams& params, GravityEstimate& estimate) {
  const double parallel_cos = cos_deg(params.axis_tolerance_deg);
  estimate.floor_height.reset();
  estimate.ceiling_height.reset();
  for (const RegionMeasurements& r : regions) {
    if (!is_large(r, params)) continue;
    const double along = r.plane_normal.dot(estimate.up);
    const double height = r.centroid.dot(estimate.up);
    // The sensor (height 0) sees a floor from above and a ceiling from below: a plane facing up
    // above it is tilted furniture (a table top at the sensor's height), not the floor.
    if (along >= parallel_cos && height < 0 &&
        (!estimate.floor_height || height < *estimate.floor_height)) {
      estimate.floor_height = height;
    }
    if (along <= -parallel_cos && height > 0 &&
        (!estimate.ceiling_height || height > *estimate.ceiling_height)) {
      estimate.ceiling_height = height;
    }
  }
}

namespace {

// Why no axis was found, with the limits that decided it.
std::string no_up_axis_message(const GravityParams& params, bool with_prior) {
  std::ostringstream s;
  s << "estimate_gravity: no plane of at least " << params.min_region_area
    << " m^2 to tell which way is up: ";
  if (with_prior) {
    s << "a floor or a ceiling (a plane within " << params.prior_tolerance_deg
      << " degrees of level for an upright camera, whose up is its -y) must be in view";
  } else {
    s << "a floor, a ceiling or a wall must be in view";
  }
  return s.str();
}

}  // namespace

GravityEstimate estimate_gravity(std::span<const RegionMeasurements> regions,
                                 const GravityParams& params) {
  const double parallel_cos = cos_deg(params.axis_tolerance_deg);
  std::optional<Eigen::Vector3d> prior;
  if (params.prior_up) {
    require(params.prior_up->norm() > 0, "estimate_gravity: prior_up must be non-zero");
    prior = params.prior_up->normalized();
  }
  // 1. The candidate axis with the most parallel or anti-parallel area, among those that make a
  // plausible room if any do.
  double best_score = -1;
  bool best_plausible = false;
  Eigen::Vector3d best_axis = Eigen::Vector3d::UnitZ();
  for (const RegionMeasurements& candidate : regions) {
    if (!is_large(candidate, params)) continue;
    const Eigen::Vector3d& axis = candidate.plane_normal;
    if (prior && std::fabs(axis.dot(*prior)) < cos_deg(params.prior_tolerance_deg)) continue;
    double score = 0;
    for (const RegionMeasurements& r : regions) {
      if (is_large(r, params) && std::fabs(r.plane_normal.dot(axis)) >= parallel_cos)
        score += r.area;
    }
    const bool plausible = plausible_room(side_extremes(regions, axis, params), params);
    if ((plausible && !best_plausible) || (plausible == best_plausible && score > best_score)) {
      best_score = score;
      best_plausible = plausible;
      best_axis = axis;
    }
  }
  if (best_score <= 0) throw Error(no_up_axis_message(params, prior.has_value()));
  Eigen::Vector3d refined = Eigen::Vector3d::Zero();
  for (const RegionMeasurements& r : regions) {
    if (!is_large(r, params)) continue;
    const double along = r.plane_normal.dot(best_axis);
    if (std::fabs(along) < parallel_cos) continue;
    refined += (along > 0 ? 1.0 : -1.0) * r.area * r.plane_normal;
  }
  GravityEstimate estimate;
  estimate.up = refined.normalized();
  if (estimate.up.dot(best_axis) < 0) estimate.up = -estimate.up;
  estimate.support_area = best_score;
  // 2. The sign: the prior's, else floor_along (normals face the sensor, so the floor's point up).
  const bool floor_along_axis = floor_along(side_extremes(regions, estimate.up, params), params);
  if (prior ? estimate.up.dot(*prior) < 0 : !floor_along_axis) estimate.up = -estimate.up;
  find_floor_and_ceiling(regions, params, estimate);
  return estimate;
}

}  // namespace kartograf::semantic
