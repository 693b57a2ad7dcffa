#include "plane_output.hpp"

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

namespace {

// The output record of a fitted plane and its pixels' sums.
Plane plane_with_sums(Label id, const SegmentPlane& fit, const PlanePixelSums& sums) {
  Plane plane = plane_record(id, fit);
  plane.extent_min = Eigen::Vector2d(sums.lo_u, sums.lo_v);
  plane.extent_max = Eigen::Vector2d(sums.hi_u, sums.hi_v);
  plane.inlier_count = sums.count;
  plane.rms_error = std::sqrt(sums.squared_error / static_cast<double>(sums.count));
  return plane;
}

}  // namespace

std::vector<PlanePixelSums> sum_plane_pixels(const PointImage& points,
                                             const std::vector<std::uint32_t>& pixel_plane,
                                             const std::vector<SegmentPlane>& fits) {
  std::vector<PlaneFrame> frames;
  for (const SegmentPlane& fit : fits) frames.push_back(PlaneFrame::of(fit));
  std::array<std::vector<PlanePixelSums>, compute::detail::kCpuChunks> chunk_sums;
  const Point4f* point = points.data();
  const std::size_t pixel_count = pixel_plane.size();
  compute::detail::for_each_chunk(pixel_count, pixel_count,
                                  [&](std::size_t begin, std::size_t end, std::size_t chunk) {
                                    std::vector<PlanePixelSums>& sums = chunk_sums[chunk];
                                    sums.assign(fits.size(), PlanePixelSums{});
                                    for (std::size_t i = begin; i < end; ++i) {
                                      const std::uint32_t m = pixel_plane[i];
                                      if (m != geometry::kNoLabel) sums[m].add(frames[m], point[i]);
                                    }
                                  });
  std::vector<PlanePixelSums> total(fits.size());
  for (const std::vector<PlanePixelSums>& sums : chunk_sums) {
    for (std::size_t m = 0; m < sums.size(); ++m) total[m].add(sums[m]);
  }
  return total;
}

void write_planes(const std::vector<SegmentPlane>& fits, const std::vector<PlanePixelSums>& sums,
                  const std::vector<std::uint32_t>& pixel_plane, std::uint64_t min_pixels,
                  PlaneSet& result) {
  std::vector<std::uint32_t> kept;
  for (std::uint32_t i = 0; i < fits.size(); ++i) {
    if (fits[i].valid && sums[i].count > 0 && sums[i].count >= min_pixels) kept.push_back(i);
  }
  std::stable_sort(kept.begin(), kept.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return sums[a].count > sums[b].count; });
  kept.resize(std::min<std::size_t>(kept.size(), std::numeric_limits<Label>::max()));
  // Indexed by a pixel's plane + 1: kNoLabel + 1 wraps to 0, unlabelled (no branch per pixel).
  static_assert(geometry::kNoLabel + 1u == 0u);
  std::vector<Label> plane_label(fits.size() + 1, kUnlabeled);
  for (std::size_t k = 0; k < kept.size(); ++k) {
    result.planes.push_back(
        plane_with_sums(static_cast<Label>(k + 1), fits[kept[k]], sums[kept[k]]));
    plane_label[kept[k] + 1] = result.planes.back().id;
  }
  Label* out = result.labels.data();
  compute::detail::for_each_chunk(pixel_plane.size(), pixel_plane.size(),
                                  [&](std::size_t begin, std::size_t end, std::size_t) {
                                    for (std::size_t i = begin; i < end; ++i)
                                      out[i] = plane_label[pixel_plane[i] + 1u];
                                  });
}

}  // namespace kartograf::segmentation::detail
