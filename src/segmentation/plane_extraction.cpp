#include "kartograf/segmentation/plane_extraction.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "cell_planes.hpp"
#include "compute/cpu_parallel.hpp"
#include "kartograf/segmentation/lab_color.hpp"
#include "plane_output.hpp"

namespace kartograf::segmentation {

namespace {

using detail::PixelPoint;
using detail::plane_record;
using detail::plane_score;
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
// The cells mode's leftover regions are 8-connected: its passes already reached across gaps.
constexpr int kCellLeftoverRadius = 1;

// Calls visit(j) for every pixel j within `radius` (Chebyshev) of pixel i, i itself included, row
// by row. A pixel away from the image's edge takes its neighbours from a table of offsets (no
// bounds per neighbour: the growths below visit each of their pixels' neighbourhoods).
class PixelNeighbourhood {
 public:
  PixelNeighbourhood(int width, int height, int radius)
      : width_(width), height_(height), radius_(radius) {
    require(radius >= 0 && radius <= kMaxRadius,
            "plane extraction: neighbourhood radius too large");
    for (int dy = -radius; dy <= radius; ++dy) {
      for (int dx = -radius; dx <= radius; ++dx) offsets_[count_++] = dy * width + dx;
    }
  }

  template <class Visit>
  void for_each(std::uint32_t i, Visit&& visit) const {
    const int x = static_cast<int>(i % static_cast<std::uint32_t>(width_));
    const int y = static_cast<int>(i / static_cast<std::uint32_t>(width_));
    if (x >= radius_ && y >= radius_ && x < width_ - radius_ && y < height_ - radius_) {
      for (int k = 0; k < count_; ++k) visit(static_cast<std::uint32_t>(int(i) + offsets_[k]));
      return;
    }
    for (int ny = std::max(0, y - radius_); ny <= std::min(height_ - 1, y + radius_); ++ny) {
      for (int nx = std::max(0, x - radius_); nx <= std::min(width_ - 1, x + radius_); ++nx)
        visit(static_cast<std::uint32_t>(ny * width_ + nx));
    }
  }

 private:
  static constexpr int kMaxRadius = 2;
  int width_, height_, radius_;
  std::array<int, (2 * kMaxRadius + 1) * (2 * kMaxRadius + 1)> offsets_{};
  int count_ = 0;
};

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
  const PixelNeighbourhood near(points.width(), points.height(), kFloodRadius);
  const Point4f* point = points.data();
  const auto open = [&](std::size_t j) {
    return pixel_plane[j] == geometry::kNoLabel && is_valid(point[j]);
  };
  // Sources: plane pixels within the radius of an unassigned valid pixel, in pixel order.
  std::vector<std::uint8_t>& source = source_mask;
  source.assign(pixel_plane.size(), 0);
  for (std::size_t i = 0; i < pixel_plane.size(); ++i) {
    if (!open(i)) continue;
    near.for_each(static_cast<std::uint32_t>(i), [&](std::uint32_t j) {
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
    near.for_each(i, [&](std::uint32_t j) {
      if (!open(j)) return;
      if (max_depth_jump > 0.0f && std::fabs(point[j].z() - depth) > max_depth_jump * depth) return;
      if (plane_score(plane, PixelPoint(point[j], params), params) >= 1.0) return;
      pixel_plane[j] = pixel_plane[i];
      queue.push_back(j);
    });
  }
}

constexpr std::uint32_t kVisited = geometry::kNoLabel - 1;  // in no plane, checked

// The moments of the region's points about `origin`: the six distinct products summed apart (the
// same sums as the outer products', a third fewer operations).
geometry::SegmentMoments region_moments(const Point4f* point,
                                        const std::vector<std::uint32_t>& region,
                                        const Eigen::Vector3d& origin) {
  std::array<double, 3> sum{};
  std::array<double, 6> outer{};  // xx, xy, xz, yy, yz, zz
  for (const std::uint32_t i : region) {
    const double x = static_cast<double>(point[i].x()) - origin.x();
    const double y = static_cast<double>(point[i].y()) - origin.y();
    const double z = static_cast<double>(point[i].z()) - origin.z();
    sum[0] += x, sum[1] += y, sum[2] += z;
    outer[0] += x * x, outer[1] += x * y, outer[2] += x * z;
    outer[3] += y * y, outer[4] += y * z, outer[5] += z * z;
  }
  geometry::SegmentMoments moments;
  moments.count = region.size();
  moments.sum = {sum[0], sum[1], sum[2]};
  moments.sum_outer << outer[0], outer[1], outer[2], outer[1], outer[3], outer[4], outer[2],
      outer[4], outer[5];
  return moments;
}

// The connected region of valid pixels that no plane took around `seed` (up to `radius` pixels
// apart, with continuous depth), marked kVisited; if it is planar it becomes a plane of its own
// (appended to `planes`), and its pixels within the plane's allowance take it.
void leftover_region(const PointImage& points, const PlaneExtractionParams& params,
                     const PixelNeighbourhood& near, std::uint32_t seed,
                     std::vector<std::uint32_t>& pixel_plane, std::vector<SegmentPlane>& planes,
                     std::vector<std::uint32_t>& region) {
  const Point4f* point = points.data();
  const float jump = params.growing.max_depth_jump;
  region.assign(1, seed);
  pixel_plane[seed] = kVisited;
  for (std::size_t head = 0; head < region.size(); ++head) {
    const std::uint32_t i = region[head];
    const float depth = point[i].z();
    near.for_each(i, [&](std::uint32_t j) {
      if (pixel_plane[j] != geometry::kNoLabel || !is_valid(point[j])) return;
      if (jump > 0.0f && std::fabs(point[j].z() - depth) > jump * depth) return;
      pixel_plane[j] = kVisited;
      region.push_back(j);
    });
  }
  // Most regions are crumbs: their moments are summed only when they are large enough.
  if (region.size() < params.min_plane_pixels) return;
  const Eigen::Vector3d origin = point[seed].head<3>().cast<double>();
  const SegmentPlane plane =
      fit_plane(region_moments(point, region, origin), origin, params.merge.fit);
  const double min_facing = std::cos(params.merge.max_incidence_deg * M_PI / 180.0);
  if (!plane.valid ||
      plane.rms_error > distance_allowance(params.merge, plane.centroid, plane.normal) ||
      std::fabs(plane.normal.dot(plane.centroid)) < min_facing * plane.centroid.norm()) {
    return;
  }
  const auto index = static_cast<std::uint32_t>(planes.size());
  planes.push_back(plane);
  for (const std::uint32_t i : region) {
    if (plane_score(plane, PixelPoint(point[i], params.merge), params.merge) < 1.0)
      pixel_plane[i] = index;
  }
}

// Connected regions of valid pixels that no plane took that are planar become planes of their
// own (leftover_region): on dark surfaces most pixels have no depth, so colour growing over
// 8-neighbours leaves only crumbs that never seed a plane. for_each_seed(visit) calls visit(i)
// for the candidate seeds in order (pixels no plane took, valid or not); `visited` collects the
// regions' pixels so that only they are unmarked at the end.
template <class ForEachSeed>
void plane_leftover_regions(const PointImage& points, const PlaneExtractionParams& params,
                            int radius, ForEachSeed&& for_each_seed,
                            std::vector<std::uint32_t>& pixel_plane,
                            std::vector<SegmentPlane>& planes, std::vector<std::uint32_t>& region,
                            std::vector<std::uint32_t>& visited) {
  const PixelNeighbourhood near(points.width(), points.height(), radius);
  visited.clear();
  for_each_seed([&](std::uint32_t seed) {
    if (pixel_plane[seed] != geometry::kNoLabel || !is_valid(points.data()[seed])) return;
    leftover_region(points, params, near, seed, pixel_plane, planes, region);
    visited.insert(visited.end(), region.begin(), region.end());
  });
  for (const std::uint32_t i : visited) {
    if (pixel_plane[i] == kVisited) pixel_plane[i] = geometry::kNoLabel;
  }
}

}  // namespace

void CellPlaneParams::validate() const {
  // Up to 64: a block's row of validity bits fits in 32 bits (cell_planes.hpp, CellGrid).
  require(cell_size >= 4 && cell_size <= 64 && cell_size % 2 == 0,
          "plane extraction: cells.cell_size must be even, 4..64 pixels, got " +
              std::to_string(cell_size));
  require(
      reach_passes >= 1 && reach_passes <= 64,
      "plane extraction: cells.reach_passes must be 1..64, got " + std::to_string(reach_passes));
  require(min_valid_fraction > 0 && min_valid_fraction <= 1,
          "plane extraction: cells.min_valid_fraction must be in (0, 1], got " +
              std::to_string(min_valid_fraction));
  require(std::isfinite(rms_base) && std::isfinite(rms_per_z2) && rms_base >= 0 &&
              rms_per_z2 >= 0 && rms_base + rms_per_z2 > 0,
          "plane extraction: cells.rms_base and cells.rms_per_z2 must be >= 0, not both 0");
  require(std::isfinite(jump_per_z2) && jump_per_z2 >= 0,
          "plane extraction: cells.jump_per_z2 must be >= 0, got " + std::to_string(jump_per_z2));
  require(std::isfinite(reference_focal) && reference_focal > 0,
          "plane extraction: cells.reference_focal must be > 0 px, got " +
              std::to_string(reference_focal));
}

void PlaneExtractionParams::validate() const {
  growing.validate();
  merge.validate();
  cells.validate();
}

PlaneExtractor::PlaneExtractor(const compute::Context& context, const PinholeIntrinsics& intrinsics,
                               const PlaneExtractionParams& params)
    : context_(&context), intrinsics_(intrinsics), params_(params), grower_(context) {
  intrinsics.validate("plane extraction");
  params.validate();
}

namespace {

void check_frame(const PointImage& points, const RgbImage& rgb, int width, int height,
                 PlaneExtractionMode mode) {
  require(!points.empty(), "plane extraction: empty input (points " +
                               size_text(points.width(), points.height()) + ")");
  require(points.width() == width && points.height() == height,
          "plane extraction: point image is " + size_text(points.width(), points.height()) +
              " but the camera is " + size_text(width, height));
  if (rgb.empty()) {
    require(mode == PlaneExtractionMode::cells,
            "plane extraction: the frame has no colour image, and the regions mode (the M1 "
            "paper's Lab region growing) needs one; the cells mode works on depth alone");
    return;
  }
  require(rgb.width() == width && rgb.height() == height,
          "plane extraction: colour image is " + size_text(rgb.width(), rgb.height()) +
              " but the camera is " + size_text(width, height));
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

namespace {

// The sums of the planes from `first` on (the leftover regions' planes) over their pixels (all
// among `visited`).
void add_leftover_sums(const PointImage& points, const std::vector<std::uint32_t>& pixel_plane,
                       const std::vector<SegmentPlane>& planes, std::size_t first,
                       const std::vector<std::uint32_t>& visited,
                       std::vector<detail::PlanePixelSums>& sums) {
  if (planes.size() == first) return;
  std::vector<detail::PlaneFrame> frames;
  for (std::size_t p = first; p < planes.size(); ++p)
    frames.push_back(detail::PlaneFrame::of(planes[p]));
  sums.resize(planes.size());
  for (const std::uint32_t i : visited) {
    const std::uint32_t p = pixel_plane[i];
    if (p != geometry::kNoLabel && p >= first) sums[p].add(frames[p - first], points.data()[i]);
  }
}

}  // namespace

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
  const auto every_pixel = [&](auto&& visit) {
    for (std::size_t i = 0; i < pixel_plane.size(); ++i) visit(static_cast<std::uint32_t>(i));
  };
  plane_leftover_regions(points, params_, kFloodRadius, every_pixel, pixel_plane, merged.planes,
                         flood_queue_, leftover_pixels_);
}

PlaneSet PlaneExtractor::extract(const PointImage& points, const RgbImage& rgb) {
  check_frame(points, rgb, intrinsics_.width, intrinsics_.height, params_.mode);
  return params_.mode == PlaneExtractionMode::cells ? extract_cells(points, rgb)
                                                    : extract_regions(points, rgb);
}

// What no cell's plane reached (thin poles, strips narrower than a cell): planar leftovers in the
// cells with pixels left become planes of their own (8-connected), as in the regions mode.
void PlaneExtractor::add_leftover_planes(const PointImage& points, const detail::CellGrid& cells,
                                         std::vector<SegmentPlane>& planes,
                                         std::vector<detail::PlanePixelSums>& sums) {
  const std::size_t cell_plane_count = planes.size();
  // Only valid pixels that no plane took can seed a region, in the same order: a row's seeds as
  // bits (the visit checks each again, since a region grown from an earlier seed takes pixels).
  const int half = cells.cell_size / 2;
  const auto pixels_of_open_cells = [&](auto&& visit) {
    for (const std::uint32_t c : open_cells_) {
      const int x0 = cells.first_x(c), y0 = cells.first_y(c);
      const int x1 = std::min(points.width(), x0 + cells.cell_size);
      const int y1 = std::min(points.height(), y0 + cells.cell_size);
      for (int y = y0; y < y1; ++y) {
        const auto row = static_cast<std::uint32_t>(y * points.width() + x0);
        std::uint64_t seeds = cells.valid_bits(x0 / half, y);
        if (x1 - x0 > half) seeds |= std::uint64_t{cells.valid_bits(x0 / half + 1, y)} << half;
        std::uint64_t untaken = 0;
        for (int j = 0; j < x1 - x0; ++j)
          untaken |= std::uint64_t{pixel_plane_[row + j] == geometry::kNoLabel} << j;
        for (seeds &= untaken; seeds != 0; seeds &= seeds - 1)
          visit(row + static_cast<std::uint32_t>(std::countr_zero(seeds)));
      }
    }
  };
  plane_leftover_regions(points, params_, kCellLeftoverRadius, pixels_of_open_cells, pixel_plane_,
                         planes, flood_queue_, leftover_pixels_);
  add_leftover_sums(points, pixel_plane_, planes, cell_plane_count, leftover_pixels_, sums);
}

PlaneSet PlaneExtractor::extract_cells(const PointImage& points, const RgbImage& rgb) {
  PlaneSet result;
  result.labels = LabelImage(intrinsics_.width, intrinsics_.height, kUnlabeled);
  Clock::time_point clock = Clock::now();
  // The moments are double sums (no fixed point to scale): any valid point is a fine origin.
  const auto first = std::find_if(points.pixels().begin(), points.pixels().end(),
                                  [](const Point4f& p) { return is_valid(p); });
  if (first == points.pixels().end()) return result;  // no valid point
  const Eigen::Vector3f origin = first->head<3>();
  // The noise terms at this camera's focal length (CellPlaneParams::reference_focal).
  CellPlaneParams cell_params = params_.cells;
  const double focal_scale = cell_params.reference_focal / intrinsics_.fx;
  cell_params.rms_per_z2 *= focal_scale;
  cell_params.jump_per_z2 *= focal_scale;
  detail::CellGrid cells;
  points_.refer_or_upload(*context_, points.pixels());  // no copy on the CPU backend
  // Without colour the cells' pass reads black; the merge then sees no colours at all.
  const bool coloured = !rgb.empty();
  if (!coloured && (no_colour_.width() != points.width() || no_colour_.height() != points.height()))
    no_colour_ = RgbImage(points.width(), points.height(), Rgb8{0, 0, 0});
  detail::measure_cells(*context_, points_, coloured ? rgb : no_colour_, cell_params.cell_size,
                        params_.growing.max_depth_jump, static_cast<float>(cell_params.jump_per_z2),
                        origin.cast<double>(), cell_buffers_, cells);
  detail::CellSegments pieces;
  result.segment_count = detail::planar_cell_segments(cell_params, params_.merge,
                                                      origin.cast<double>(), cells, pieces);
  result.timings.moments = elapsed_ms(clock);
  if (result.segment_count == 0) return result;

  // Merging takes what the cells know: adjacency, fits and pixel sums (no pass over the pixels).
  const SegmentGraph graph = detail::cell_segment_graph(cells, result.segment_count);
  // No label image: a pixel's segment is its cell's or block's.
  MergedPlanes merged =
      merge_segments(SegmentLabelImage(), pieces.moments, params_.merge,
                     {coloured ? std::span<const Eigen::Vector3f>(pieces.lab_colours)
                               : std::span<const Eigen::Vector3f>(),
                      &points, &graph, pieces.fits, pieces.pixel_sums,
                      [&cells](int x, int y) { return cells.segment_at(x, y); }});
  result.merged_count = static_cast<std::uint32_t>(merged.planes.size());
  result.timings.merging = elapsed_ms(clock);

  // The assignment sums each plane's pixels as it goes: no second pass over the points.
  std::vector<detail::PlanePixelSums> sums = detail::assign_cell_pixels(
      *context_, points_, cell_buffers_, points, cells, merged.segment_plane, merged.planes,
      origin.cast<double>(), params_.merge, params_.cells.reach_passes, pixel_plane_, open_cells_);
  if (params_.cells.leftover_planes) add_leftover_planes(points, cells, merged.planes, sums);
  result.timings.refinement = elapsed_ms(clock);

  detail::write_planes(merged.planes, sums, pixel_plane_, params_.min_plane_pixels, result);
  result.timings.output = elapsed_ms(clock);
  return result;
}

PlaneSet PlaneExtractor::extract_regions(const PointImage& points, const RgbImage& rgb) {
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

  detail::write_planes(merged.planes, detail::sum_plane_pixels(points, pixel_plane_, merged.planes),
                       pixel_plane_, params_.min_plane_pixels, result);
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
