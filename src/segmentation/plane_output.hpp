#pragma once
// What both plane extraction modes (plane_extraction.hpp) share at the pixel level: a pixel's
// score against a plane, and the output planes with their labels, extents and errors.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/point_image.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"

namespace kartograf::segmentation::detail {

// A pixel's point with what every plane's distance allowance there needs.
struct PixelPoint {
  Eigen::Vector3d p;
  double inverse_range;  // 1 / |p|
  double base;           // distance_base + distance_per_z2 z^2

  PixelPoint(const Point4f& point, const PlaneMergeParams& params)
      : p(point.head<3>().cast<double>()),
        inverse_range(1.0 / p.norm()),
        base(params.distance_base + params.distance_per_z2 * p.z() * p.z()) {}
};

inline  // Distance of the pixel's point to the plane over the merge's distance allowance there (<
        // 1:
    // within it); distance_allowance without its square root per plane.
    double
    plane_score(const SegmentPlane& plane, const PixelPoint& pixel,
                const PlaneMergeParams& params) {
  const double along = plane.normal.dot(pixel.p);
  const double facing = std::max(std::fabs(along) * pixel.inverse_range, params.min_facing_factor);
  return std::fabs(along + plane.offset) / (pixel.base * facing);
}

// The output record of a fitted plane (extents and counts filled by the caller).
Plane plane_record(Label id, const SegmentPlane& fit);

// The output planes: valid, with at least min_pixels pixels, by decreasing size (then index
// order), ids 1..n (extents and counts to be measured); plane_label: each fitted plane's id.
void output_planes(const std::vector<SegmentPlane>& fits,
                   const std::vector<std::uint32_t>& pixel_plane, std::uint64_t min_pixels,
                   std::vector<Plane>& planes, std::vector<Label>& plane_label);

// Labels, extents, inlier counts and errors of the output planes: per chunk, combined in chunk
// order (the same sums for any thread count).
void measure_planes(const PointImage& points, const std::vector<std::uint32_t>& pixel_plane,
                    const std::vector<Label>& plane_label, PlaneSet& result);

// result's planes (output_planes) and labels, extents, counts and errors (measure_planes).
void write_planes(const PointImage& points, const std::vector<SegmentPlane>& fits,
                  const std::vector<std::uint32_t>& pixel_plane, std::uint64_t min_pixels,
                  PlaneSet& result);

}  // namespace kartograf::segmentation::detail
