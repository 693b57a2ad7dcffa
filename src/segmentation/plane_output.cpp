#include "plane_output.hpp"

#include <array>
#include <limits>

#include "compute/cpu_parallel.hpp"

namespace kartograf::segmentation::detail {

Plane plane_record(Label id, const SegmentPlane& fit) {
  Plane plane;
  plane.id = id;
  plane.normal = fit.normal;
  plane.offset = fit.offset;
  plane.centroid = fit.centroid;
  plane.major_axis = fit.major_axis;
  plane.minor_axis = fit.minor_axis;
  return plane;
}

void output_planes(const std::vector<SegmentPlane>& fits,
                   const std::vector<std::uint32_t>& pixel_plane, std::uint64_t min_pixels,
                   std::vector<Plane>& planes, std::vector<Label>& plane_label) {
  std::vector<std::uint64_t> pixels_of(fits.size(), 0);
  for (const std::uint32_t m : pixel_plane) {
    if (m != geometry::kNoLabel) ++pixels_of[m];
  }
  std::vector<std::uint32_t> kept;
  for (std::uint32_t i = 0; i < fits.size(); ++i) {
    if (fits[i].valid && pixels_of[i] >= min_pixels) kept.push_back(i);
  }
  std::stable_sort(kept.begin(), kept.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return pixels_of[a] > pixels_of[b]; });
  kept.resize(std::min<std::size_t>(kept.size(), std::numeric_limits<Label>::max()));
  plane_label.assign(fits.size(), kUnlabeled);
  for (std::size_t k = 0; k < kept.size(); ++k) {
    Plane plane = plane_record(static_cast<Label>(k + 1), fits[kept[k]]);
    plane.extent_min = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    plane.extent_max = -plane.extent_min;
    planes.push_back(plane);
    plane_label[kept[k]] = plane.id;
  }
}

void measure_planes(const PointImage& points, const std::vector<std::uint32_t>& pixel_plane,
                    const std::vector<Label>& plane_label, PlaneSet& result) {
  struct PlaneSums {
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d hi = -lo;
    double squared_error = 0;
    std::uint64_t count = 0;
  };
  std::array<std::vector<PlaneSums>, compute::detail::kCpuChunks> chunk_sums;
  const Point4f* point = points.data();
  Label* out = result.labels.data();
  const std::size_t pixel_count = pixel_plane.size();
  compute::detail::for_each_chunk(
      pixel_count, pixel_count, [&](std::size_t begin, std::size_t end, std::size_t chunk) {
        std::vector<PlaneSums>& sums = chunk_sums[chunk];
        sums.assign(result.planes.size(), PlaneSums{});
        for (std::size_t i = begin; i < end; ++i) {
          if (pixel_plane[i] == geometry::kNoLabel) continue;
          const Label id = plane_label[pixel_plane[i]];
          if (id == kUnlabeled) continue;
          out[i] = id;
          const Plane& plane = result.planes[id - 1];
          PlaneSums& sum = sums[id - 1];
          const Eigen::Vector3d d = point[i].head<3>().cast<double>() - plane.centroid;
          const Eigen::Vector2d uv(d.dot(plane.major_axis), d.dot(plane.minor_axis));
          sum.lo = sum.lo.cwiseMin(uv);
          sum.hi = sum.hi.cwiseMax(uv);
          const double distance = d.dot(plane.normal);
          sum.squared_error += distance * distance;
          ++sum.count;
        }
      });
  for (Plane& plane : result.planes) {
    double squared_error = 0;
    for (const std::vector<PlaneSums>& sums : chunk_sums) {
      const PlaneSums& sum = sums[plane.id - 1];
      plane.extent_min = plane.extent_min.cwiseMin(sum.lo);
      plane.extent_max = plane.extent_max.cwiseMax(sum.hi);
      squared_error += sum.squared_error;
      plane.inlier_count += sum.count;
    }
    plane.rms_error = std::sqrt(squared_error / static_cast<double>(plane.inlier_count));
  }
}

void write_planes(const PointImage& points, const std::vector<SegmentPlane>& fits,
                  const std::vector<std::uint32_t>& pixel_plane, std::uint64_t min_pixels,
                  PlaneSet& result) {
  std::vector<Label> plane_label;
  output_planes(fits, pixel_plane, min_pixels, result.planes, plane_label);
  measure_planes(points, pixel_plane, plane_label, result);
}

}  // namespace kartograf::segmentation::detail
