#include "kartograf/semantic/gravity.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include "kartograf/core/error.hpp"

namespace kartograf::semantic {
namespace {

double cos_deg(double degrees) {
  return std::cos(degrees * std::numbers::pi / 180.0);
}

bool is_large(const RegionMeasurements& r, const GravityParams& params) {
  return r.area >= params.min_region_area;
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
    if (along >= parallel_cos && (!estimate.floor_height || height < *estimate.floor_height)) {
      estimate.floor_height = height;
    }
    if (along <= -parallel_cos && (!estimate.ceiling_height || height > *estimate.ceiling_height)) {
      estimate.ceiling_height = height;
    }
  }
}

GravityEstimate estimate_gravity(std::span<const RegionMeasurements> regions,
                                 const GravityParams& params) {
  const double parallel_cos = cos_deg(params.axis_tolerance_deg);
  std::optional<Eigen::Vector3d> prior;
  if (params.prior_up) {
    require(params.prior_up->norm() > 0, "estimate_gravity: prior_up must be non-zero");
    prior = params.prior_up->normalized();
  }
  // 1. The candidate axis with the most parallel or anti-parallel area.
  double best_score = -1;
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
    if (score > best_score) {
      best_score = score;
      best_axis = axis;
    }
  }
  require(best_score > 0, "estimate_gravity: no region of at least " +
                              std::to_string(params.min_region_area) +
                              " m^2 (within the prior's tolerance) to vote for the up axis");
  Eigen::Vector3d refined = Eigen::Vector3d::Zero();
  double nearest_distance = std::numeric_limits<double>::infinity();
  Eigen::Vector3d nearest_normal = best_axis;
  for (const RegionMeasurements& r : regions) {
    if (!is_large(r, params)) continue;
    const double along = r.plane_normal.dot(best_axis);
    if (std::fabs(along) < parallel_cos) continue;
    refined += (along > 0 ? 1.0 : -1.0) * r.area * r.plane_normal;
    // Distance from the sensor (origin) to the region's plane.
    const double distance = std::fabs(r.centroid.dot(r.plane_normal));
    if (distance < nearest_distance) {
      nearest_distance = distance;
      nearest_normal = r.plane_normal;
    }
  }
  GravityEstimate estimate;
  estimate.up = refined.normalized();
  estimate.support_area = best_score;
  // 2. The sign: the prior's, else up along the normal of the nearest supporting plane (normals
  // face the sensor, so the nearest plane, taken as the floor, has its normal pointing up).
  const Eigen::Vector3d sign_reference = prior ? *prior : nearest_normal;
  if (estimate.up.dot(sign_reference) < 0) estimate.up = -estimate.up;
  find_floor_and_ceiling(regions, params, estimate);
  return estimate;
}

}  // namespace kartograf::semantic
