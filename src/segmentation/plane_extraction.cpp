#include "kartograf/segmentation/plane_extraction.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "compute/cpu_parallel.hpp"
#include "kartograf/segmentation/lab_color.hpp"

namespace kartograf::segmentation {

namespace {

using Clock = std::chrono::steady_clock;

double elapsed_ms(Clock::time_point& since) {
  const Clock::time_point now = Clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - since).count();
  since = now;
  return ms;
}

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// The centre of the valid points' bounding box and the half extent (plus a margin), for the
// fixed-point moments. False when no point is valid.
bool moment_frame(const PointImage& points, Eigen::Vector3f& origin, float& max_offset) {
  constexpr float kInfinity = std::numeric_limits<float>::infinity();
  std::array<Eigen::Array3f, compute::detail::kCpuChunks> chunk_lo, chunk_hi;
  chunk_lo.fill(Eigen::Array3f::Constant(kInfinity));
  chunk_hi.fill(Eigen::Array3f::Constant(-kInfinity));
  compute::detail::for_each_chunk(points.size(), points.size(),
                                  [&](std::size_t begin, std::size_t end, std::size_t chunk) {
                                    Eigen::Array3f lo = chunk_lo[chunk], hi = chunk_hi[chunk];
                                    for (std::size_t i = begin; i < end; ++i) {
                                      const Point4f& p = points.data()[i];
                                      if (!is_valid(p)) continue;
                                      lo = lo.min(p.head<3>().array());
                                      hi = hi.max(p.head<3>().array());
                                    }
                                    chunk_lo[chunk] = lo, chunk_hi[chunk] = hi;
                                  });
  Eigen::Array3f lo = chunk_lo[0], hi = chunk_hi[0];
  for (std::size_t c = 1; c < chunk_lo.size(); ++c)
    lo = lo.min(chunk_lo[c]), hi = hi.max(chunk_hi[c]);
  if (!(lo <= hi).all()) return false;
  require(lo.isFinite().all() && hi.isFinite().all(),
          "plane extraction: a point has an infinite coordinate");
  origin = (0.5f * (lo + hi)).matrix();
  max_offset = 0.5f * (hi - lo).maxCoeff() * 1.01f + 0.01f;
  return true;
}

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
double plane_score(const SegmentPlane& plane, const PixelPoint& pixel,
                   const PlaneMergeParams& params) {
  const double along = plane.normal.dot(pixel.p);
  const double facing = std::max(std::fabs(along) * pixel.inverse_range, params.min_facing_factor);
  return std::fabs(along + plane.offset) / (pixel.base * facing);
}

// Pixels of segments along plane borders (left out of every plane, or touching another plane's
// segments: mixed pieces along edges and creases) go to the plane, among their own and those of
// the neighbouring segments, with the lowest score below 1; a plane's own pixels otherwise stay.
// Plane fits are unchanged.
void refine_border_pixels(const SegmentLabelImage& segments, const PointImage& points,
                          const MergedPlanes& merged, const PlaneMergeParams& params,
                          std::vector<std::uint32_t>& pixel_plane) {
  const SegmentGraph& graph = merged.graph;
  const auto segment_count = static_cast<std::uint32_t>(merged.segment_plane.size());
  // Per segment, the other planes among its neighbours' (distinct, in graph order): segments
  // with none are not on a border.
  std::vector<std::uint32_t> candidate_start(std::size_t{segment_count} + 1, 0);
  std::vector<std::uint32_t> candidates;
  for (std::uint32_t s = 0; s < segment_count; ++s) {
    const std::uint32_t own = merged.segment_plane[s];
    const std::size_t first = candidates.size();
    for (std::uint32_t k = graph.offsets[s]; k < graph.offsets[s + 1]; ++k) {
      const std::uint32_t other = merged.segment_plane[graph.neighbours[k]];
      if (other == geometry::kNoLabel || other == own ||
          std::find(candidates.begin() + static_cast<std::ptrdiff_t>(first), candidates.end(),
                    other) != candidates.end()) {
        continue;
      }
      candidates.push_back(other);
    }
    candidate_start[s + 1] = static_cast<std::uint32_t>(candidates.size());
  }
  const std::uint32_t* segment = segments.data();
  compute::detail::for_each_chunk(
      segments.size(), segments.size(), [&](std::size_t begin, std::size_t end, std::size_t) {
        for (std::size_t i = begin; i < end; ++i) {
          const std::uint32_t s = segment[i];
          if (s == geometry::kNoLabel || candidate_start[s] == candidate_start[s + 1]) continue;
          const PixelPoint p(points.data()[i], params);
          const std::uint32_t own = pixel_plane[i];
          double best = own == geometry::kNoLabel
                            ? 1.0
                            : std::min(1.0, plane_score(merged.planes[own], p, params));
          for (std::uint32_t k = candidate_start[s]; k < candidate_start[s + 1]; ++k) {
            const double score = plane_score(merged.planes[candidates[k]], p, params);
            if (score < best) best = score, pixel_plane[i] = candidates[k];
          }
        }
      });
}

// How far apart [pixels] the refinement's growth and left-over regions connect pixels: across a
// one-pixel gap of missing depth.
constexpr int kFloodRadius = 2;

// Calls visit(j) for every pixel j within `radius` (Chebyshev) of pixel i, i itself included.
template <class Visit>
void for_each_pixel_near(std::uint32_t i, int width, int height, int radius, Visit&& visit) {
  const int x = static_cast<int>(i % static_cast<std::uint32_t>(width));
  const int y = static_cast<int>(i / static_cast<std::uint32_t>(width));
  for (int ny = std::max(0, y - radius); ny <= std::min(height - 1, y + radius); ++ny) {
    for (int nx = std::max(0, x - radius); nx <= std::min(width - 1, x + radius); ++nx)
      visit(static_cast<std::uint32_t>(ny * width + nx));
  }
}

// The output record of a fitted plane (extents and counts filled by the caller).
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

// Planes grow pixel by pixel (breadth first) into valid pixels that no plane took, while a pixel
// lies within the distance allowance of the plane it is reached from and its depth continues that
// pixel's (|dz| <= max_depth_jump z; 0: no test). Dark or finely textured surfaces fall apart into
// colour segments too small to merge, and on dark ones most pixels have no depth: the growth
// reaches up to kFloodRadius pixels, across the gaps.
void flood_unassigned_pixels(const PointImage& points, const std::vector<SegmentPlane>& planes,
                             const PlaneMergeParams& params, float max_depth_jump,
                             std::vector<std::uint32_t>& pixel_plane,
                             std::vector<std::uint32_t>& queue,
                             std::vector<std::uint8_t>& source_mask) {
  const int width = points.width(), height = points.height();
  const Point4f* point = points.data();
  const auto open = [&](std::size_t j) {
    return pixel_plane[j] == geometry::kNoLabel && is_valid(point[j]);
  };
  // Sources: plane pixels within the radius of an unassigned valid pixel, in pixel order.
  std::vector<std::uint8_t>& source = source_mask;
  source.assign(pixel_plane.size(), 0);
  for (std::size_t i = 0; i < pixel_plane.size(); ++i) {
    if (!open(i)) continue;
    for_each_pixel_near(static_cast<std::uint32_t>(i), width, height, kFloodRadius,
                        [&](std::uint32_t j) {
                          if (pixel_plane[j] != geometry::kNoLabel) source[j] = 1;
                        });
  }
  queue.clear();
  for (std::size_t i = 0; i < pixel_plane.size(); ++i) {
    if (source[i]) queue.push_back(static_cast<std::uint32_t>(i));
  }
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::uint32_t i = queue[head];
    const SegmentPlane& plane = planes[pixel_plane[i]];
    const float depth = point[i].z();
    for_each_pixel_near(i, width, height, kFloodRadius, [&](std::uint32_t j) {
      if (!open(j)) return;
      if (max_depth_jump > 0.0f && std::fabs(point[j].z() - depth) > max_depth_jump * depth) return;
      if (plane_score(plane, PixelPoint(point[j], params), params) >= 1.0) return;
      pixel_plane[j] = pixel_plane[i];
      queue.push_back(j);
    });
  }
}

// Connected regions of valid pixels that no plane took (up to kFloodRadius pixels apart, with
// continuous depth) that are planar become planes of their own: on dark surfaces most pixels have
// no depth, so colour growing over 8-neighbours leaves only crumbs that never seed a plane.
void plane_leftover_regions(const PointImage& points, const PlaneExtractionParams& params,
                            std::vector<std::uint32_t>& pixel_plane,
                            std::vector<SegmentPlane>& planes, std::vector<std::uint32_t>& region) {
  const int width = points.width(), height = points.height();
  const Point4f* point = points.data();
  const float jump = params.growing.max_depth_jump;
  const double min_facing = std::cos(params.merge.max_incidence_deg * M_PI / 180.0);
  constexpr std::uint32_t kVisited = geometry::kNoLabel - 1;  // in no plane, checked
  for (std::size_t seed = 0; seed < pixel_plane.size(); ++seed) {
    if (pixel_plane[seed] != geometry::kNoLabel || !is_valid(point[seed])) continue;
    region.assign(1, static_cast<std::uint32_t>(seed));
    pixel_plane[seed] = kVisited;
    geometry::SegmentMoments moments;
    const Eigen::Vector3d origin = point[seed].head<3>().cast<double>();
    for (std::size_t head = 0; head < region.size(); ++head) {
      const std::uint32_t i = region[head];
      const Eigen::Vector3d d = point[i].head<3>().cast<double>() - origin;
      ++moments.count;
      moments.sum += d;
      moments.sum_outer += d * d.transpose();
      const float depth = point[i].z();
      for_each_pixel_near(i, width, height, kFloodRadius, [&](std::uint32_t j) {
        if (pixel_plane[j] != geometry::kNoLabel || !is_valid(point[j])) return;
        if (jump > 0.0f && std::fabs(point[j].z() - depth) > jump * depth) return;
        pixel_plane[j] = kVisited;
        region.push_back(j);
      });
    }
    if (moments.count < params.min_plane_pixels) continue;
    const SegmentPlane plane = fit_plane(moments, origin, params.merge.fit);
    if (!plane.valid ||
        plane.rms_error > distance_allowance(params.merge, plane.centroid, plane.normal) ||
        std::fabs(plane.normal.dot(plane.centroid)) < min_facing * plane.centroid.norm()) {
      continue;
    }
    const auto index = static_cast<std::uint32_t>(planes.size());
    planes.push_back(plane);
    for (const std::uint32_t i : region) {
      if (plane_score(plane, PixelPoint(point[i], params.merge), params.merge) < 1.0)
        pixel_plane[i] = index;
    }
  }
  for (std::uint32_t& p : pixel_plane) {
    if (p == kVisited) p = geometry::kNoLabel;
  }
}

}  // namespace

void PlaneExtractionParams::validate() const {
  growing.validate();
  merge.validate();
}

PlaneExtractor::PlaneExtractor(const compute::Context& context, const PinholeIntrinsics& intrinsics,
                               const PlaneExtractionParams& params)
    : context_(&context), intrinsics_(intrinsics), params_(params), grower_(context) {
  intrinsics.validate("plane extraction");
  params.validate();
}

namespace {

void check_frame(const PointImage& points, const RgbImage& rgb, int width, int height) {
  require(!points.empty() && !rgb.empty(),
          "plane extraction: empty input (points " + size_text(points.width(), points.height()) +
              ", colour " + size_text(rgb.width(), rgb.height()) + ")");
  require(points.width() == width && points.height() == height,
          "plane extraction: point image is " + size_text(points.width(), points.height()) +
              " but the camera is " + size_text(width, height));
  require(rgb.width() == width && rgb.height() == height,
          "plane extraction: colour image is " + size_text(rgb.width(), rgb.height()) +
              " but the camera is " + size_text(width, height));
}

// The output planes: valid, with at least min_pixels pixels, by decreasing size (then merge
// order), ids 1..n (extents and counts to be measured); plane_label: each merged plane's id.
void output_planes(const MergedPlanes& merged, const std::vector<std::uint32_t>& pixel_plane,
                   std::uint64_t min_pixels, std::vector<Plane>& planes,
                   std::vector<Label>& plane_label) {
  std::vector<std::uint64_t> pixels_of(merged.planes.size(), 0);
  for (const std::uint32_t m : pixel_plane) {
    if (m != geometry::kNoLabel) ++pixels_of[m];
  }
  std::vector<std::uint32_t> kept;
  for (std::uint32_t i = 0; i < merged.planes.size(); ++i) {
    if (merged.planes[i].valid && pixels_of[i] >= min_pixels) kept.push_back(i);
  }
  std::stable_sort(kept.begin(), kept.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return pixels_of[a] > pixels_of[b]; });
  kept.resize(std::min<std::size_t>(kept.size(), std::numeric_limits<Label>::max()));
  plane_label.assign(merged.planes.size(), kUnlabeled);
  for (std::size_t k = 0; k < kept.size(); ++k) {
    Plane plane = plane_record(static_cast<Label>(k + 1), merged.planes[kept[k]]);
    plane.extent_min = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    plane.extent_max = -plane.extent_min;
    planes.push_back(plane);
    plane_label[kept[k]] = plane.id;
  }
}

// Labels, extents, inlier counts and errors of the output planes: per chunk, combined in chunk
// order (the same sums for any thread count).
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

}  // namespace

std::uint32_t PlaneExtractor::grow_segments(const PointImage& points,
                                            geometry::SegmentMomentSet& moments) {
  points_.refer_or_upload(*context_, points.pixels());  // no copy on the CPU backend
  const std::uint32_t count =
      grower_.grow(lab_, points_, params_.growing, &statistics_, &moments.origin);
  if (segments_.width() != points.width() || segments_.height() != points.height())
    segments_ = SegmentLabelImage(points.width(), points.height());
  grower_.labels().download(segments_.pixels());
  moments.segments = std::move(statistics_.moments);
  return count;
}

void PlaneExtractor::assign_pixels(const PointImage& points, MergedPlanes& merged) {
  const SegmentLabelImage& segments = segments_;
  std::vector<std::uint32_t>& pixel_plane = pixel_plane_;
  pixel_plane.assign(segments.size(), geometry::kNoLabel);
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const std::uint32_t s = segments.data()[i];
    if (s != geometry::kNoLabel) pixel_plane[i] = merged.segment_plane[s];
  }
  if (!params_.refine_pixels) return;
  refine_border_pixels(segments, points, merged, params_.merge, pixel_plane);
  flood_unassigned_pixels(points, merged.planes, params_.merge, params_.growing.max_depth_jump,
                          pixel_plane, flood_queue_, flood_sources_);
  plane_leftover_regions(points, params_, pixel_plane, merged.planes, flood_queue_);
}

PlaneSet PlaneExtractor::extract(const PointImage& points, const RgbImage& rgb) {
  check_frame(points, rgb, intrinsics_.width, intrinsics_.height);
  PlaneSet result;
  result.labels = LabelImage(intrinsics_.width, intrinsics_.height, kUnlabeled);
  Clock::time_point clock = Clock::now();
  to_lab_codes(rgb, lab_);
  result.timings.lab = elapsed_ms(clock);

  // Segments with their colours and moments, summed as they grow.
  Eigen::Vector3f origin;
  float max_offset = 0;
  if (!moment_frame(points, origin, max_offset)) return result;  // no valid point
  geometry::SegmentMomentSet moments;
  moments.origin = origin.cast<double>();
  result.segment_count = grow_segments(points, moments);
  result.timings.growing = elapsed_ms(clock);
  if (result.segment_count == 0) return result;

  MergedPlanes merged =
      merge_segments(segments_, moments, params_.merge, {statistics_.colours, &points});
  result.merged_count = static_cast<std::uint32_t>(merged.planes.size());
  result.timings.merging = elapsed_ms(clock);

  assign_pixels(points, merged);
  result.timings.refinement = elapsed_ms(clock);

  std::vector<Label> plane_label;
  output_planes(merged, pixel_plane_, params_.min_plane_pixels, result.planes, plane_label);
  measure_planes(points, pixel_plane_, plane_label, result);
  result.timings.output = elapsed_ms(clock);
  return result;
}

PlaneSet fit_segment_planes(const PointImage& points, const SegmentLabelImage& segments,
                            std::uint32_t segment_count, std::uint64_t min_pixels) {
  require(points.width() == segments.width() && points.height() == segments.height(),
          "segment planes: point image is " + size_text(points.width(), points.height()) +
              " but the segments are " + size_text(segments.width(), segments.height()));
  PlaneSet result;
  result.labels = LabelImage(points.width(), points.height(), kUnlabeled);
  result.segment_count = segment_count;
  result.merged_count = segment_count;
  if (segment_count == 0) return result;
  geometry::SegmentMomentParams params;
  params.label_count = segment_count;
  Eigen::Vector3f origin;
  if (!moment_frame(points, origin, params.max_offset)) return result;
  params.origin = origin;
  const geometry::SegmentMomentSet moments =
      geometry::segment_moments(points.pixels(), segments.pixels(), params);
  std::vector<Label> plane_of(segment_count, kUnlabeled);
  for (std::uint32_t s = 0; s < segment_count; ++s) {
    const SegmentPlane fit = fit_plane(moments.segments[s], moments.origin);
    if (!fit.valid || fit.count < min_pixels ||
        result.planes.size() >= std::numeric_limits<Label>::max()) {
      continue;
    }
    Plane plane = plane_record(static_cast<Label>(result.planes.size() + 1), fit);
    plane.inlier_count = fit.count;
    plane.rms_error = fit.rms_error;
    const Eigen::Vector2d half(std::sqrt(3.0) * fit.major_sigma, std::sqrt(3.0) * fit.minor_sigma);
    plane.extent_min = -half;  // of a uniform rectangle with the segment's spread
    plane.extent_max = half;
    plane_of[s] = plane.id;
    result.planes.push_back(plane);
  }
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const std::uint32_t s = segments.data()[i];
    if (s != geometry::kNoLabel) result.labels.data()[i] = plane_of[s];
  }
  return result;
}

}  // namespace kartograf::segmentation
