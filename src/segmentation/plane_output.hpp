#pragma once
// What both plane extraction modes (plane_extraction.hpp) share at the pixel level: a pixel's
// score against a plane, what each plane's pixels sum up to, and the output planes and labels.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
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

// Distance of the pixel's point to the plane over the merge's distance allowance there (< 1:
// within it); distance_allowance without its square root per plane.
inline double plane_score(const SegmentPlane& plane, const PixelPoint& pixel,
                          const PlaneMergeParams& params) {
  const double along = plane.normal.dot(pixel.p);
  const double facing = std::max(std::fabs(along) * pixel.inverse_range, params.min_facing_factor);
  return std::fabs(along + plane.offset) / (pixel.base * facing);
}

// A fitted plane's in-plane frame in float, compact: what the per-pixel sums read.
struct PlaneFrame {
  Eigen::Vector3f centroid, major, minor, normal;
  static PlaneFrame of(const SegmentPlane& fit) {
    return {fit.centroid.cast<float>(), fit.major_axis.cast<float>(), fit.minor_axis.cast<float>(),
            fit.normal.cast<float>()};
  }
};

// What a plane's pixels give its output record: their extent in its in-plane frame, their
// squared distances to it and their count.
struct PlanePixelSums {
  float lo_u = std::numeric_limits<float>::infinity(), lo_v = lo_u;
  float hi_u = -lo_u, hi_v = -lo_u;
  double squared_error = 0;
  std::uint64_t count = 0;

  void add(const PlaneFrame& frame, const Point4f& point) {
    const Eigen::Vector3f d = point.head<3>() - frame.centroid;
    extend(d.dot(frame.major), d.dot(frame.minor));
    const float w = d.dot(frame.normal);
    squared_error += double{w} * w;
    ++count;
  }
  // The extent alone (the point's count and error added otherwise).
  void extend(const PlaneFrame& frame, const Point4f& point) {
    const Eigen::Vector3f d = point.head<3>() - frame.centroid;
    extend(d.dot(frame.major), d.dot(frame.minor));
  }
  void extend(float u, float v) {
    lo_u = std::min(lo_u, u), hi_u = std::max(hi_u, u);
    lo_v = std::min(lo_v, v), hi_v = std::max(hi_v, v);
  }
  void add(const PlanePixelSums& other) {
    lo_u = std::min(lo_u, other.lo_u), hi_u = std::max(hi_u, other.hi_u);
    lo_v = std::min(lo_v, other.lo_v), hi_v = std::max(hi_v, other.hi_v);
    squared_error += other.squared_error;
    count += other.count;
  }
};

// The output record of a fitted plane (extents and counts filled by the caller).
Plane plane_record(Label id, const SegmentPlane& fit);

// The sums of every fitted plane's pixels (pixel_plane: an index into fits, or kNoLabel): per
// chunk, combined in chunk order (the same sums for any thread count).
std::vector<PlanePixelSums> sum_plane_pixels(const PointImage& points,
                                             const std::vector<std::uint32_t>& pixel_plane,
                                             const std::vector<SegmentPlane>& fits);

// result's planes (valid fits with at least min_pixels pixels, by decreasing count, then fit
// order; ids 1..n) with their extents, counts and errors, and its labels.
void write_planes(const std::vector<SegmentPlane>& fits, const std::vector<PlanePixelSums>& sums,
                  const std::vector<std::uint32_t>& pixel_plane, std::uint64_t min_pixels,
                  PlaneSet& result);

}  // namespace kartograf::segmentation::detail
