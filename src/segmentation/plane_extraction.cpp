#include "kartograf/segmentation/plane_extraction.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

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
  Eigen::Array3f lo = Eigen::Array3f::Constant(std::numeric_limits<float>::infinity());
  Eigen::Array3f hi = -lo;
  for (const Point4f& p : points.pixels()) {
    if (!is_valid(p)) continue;
    lo = lo.min(p.head<3>().array());
    hi = hi.max(p.head<3>().array());
  }
  if (!(lo <= hi).all()) return false;
  require(lo.isFinite().all() && hi.isFinite().all(),
          "plane extraction: a point has an infinite coordinate");
  origin = (0.5f * (lo + hi)).matrix();
  max_offset = 0.5f * (hi - lo).maxCoeff() * 1.01f + 0.01f;
  return true;
}

}  // namespace

void PlaneExtractionParams::validate() const {
  require(std::isfinite(growing.lab_threshold) && growing.lab_threshold > 0,
          "plane extraction: growing.lab_threshold must be positive");
  require(std::isfinite(growing.max_depth_jump) && growing.max_depth_jump >= 0,
          "plane extraction: growing.max_depth_jump must be >= 0");
  merge.validate();
}

PlaneExtractor::PlaneExtractor(const compute::Context& context, const PinholeIntrinsics& intrinsics,
                               const PlaneExtractionParams& params)
    : context_(&context), intrinsics_(intrinsics), params_(params), fitter_(context) {
  intrinsics.validate("plane extraction");
  params.validate();
}

PlaneSet PlaneExtractor::extract(const PointImage& points, const RgbImage& rgb) {
  const int width = intrinsics_.width, height = intrinsics_.height;
  require(!points.empty() && !rgb.empty(),
          "plane extraction: empty input (points " + size_text(points.width(), points.height()) +
              ", colour " + size_text(rgb.width(), rgb.height()) + ")");
  require(points.width() == width && points.height() == height,
          "plane extraction: point image is " + size_text(points.width(), points.height()) +
              " but the camera is " + size_text(width, height));
  require(rgb.width() == width && rgb.height() == height,
          "plane extraction: colour image is " + size_text(rgb.width(), rgb.height()) +
              " but the camera is " + size_text(width, height));

  PlaneSet result;
  result.labels = LabelImage(width, height, kUnlabeled);
  Clock::time_point clock = Clock::now();
  const LabImage lab = to_lab(rgb);
  result.timings.lab = elapsed_ms(clock);
  const SegmentLabelImage segments = grow_regions_lab(lab, points, params_.growing);
  result.segment_count = segment_count(segments);
  result.timings.growing = elapsed_ms(clock);

  Eigen::Vector3f origin;
  float max_offset = 0;
  if (result.segment_count == 0 || !moment_frame(points, origin, max_offset)) return result;
  if (points_.size() != points.size()) points_ = compute::Buffer<Point4f>(*context_, points.size());
  points_.upload(points.pixels());
  const geometry::SegmentMomentSet moments =
      fitter_.moments(points_, segments.pixels(), result.segment_count, origin, max_offset);
  result.timings.moments = elapsed_ms(clock);

  const MergedPlanes merged = merge_segments(segments, moments, params_.merge);
  result.merged_count = static_cast<std::uint32_t>(merged.planes.size());
  result.timings.merging = elapsed_ms(clock);

  // Pixel refinement along plane borders: a pixel of a segment that no plane took (mixed pieces
  // along edges and creases) or that touches a segment of another plane goes to the plane, among
  // its own and those of the neighbouring segments, nearest in distance over allowance (< 1; a
  // plane's own pixels otherwise stay). Plane fits are unchanged.
  const std::size_t pixel_count = segments.size();
  const std::uint32_t* segment = segments.data();
  const Point4f* point = points.data();
  std::vector<std::uint32_t>& pixel_plane = pixel_plane_;
  pixel_plane.assign(pixel_count, geometry::kNoLabel);
  for (std::size_t i = 0; i < pixel_count; ++i) {
    if (segment[i] != geometry::kNoLabel) pixel_plane[i] = merged.segment_plane[segment[i]];
  }
  if (params_.refine_pixels) {
    const SegmentGraph& graph = merged.graph;
    std::vector<std::uint8_t> on_border(result.segment_count, 0);
    for (std::uint32_t s = 0; s < result.segment_count; ++s) {
      const std::uint32_t own = merged.segment_plane[s];
      for (std::uint32_t k = graph.offsets[s]; k < graph.offsets[s + 1] && !on_border[s]; ++k) {
        const std::uint32_t other = merged.segment_plane[graph.neighbours[k]];
        on_border[s] = other != geometry::kNoLabel && other != own;
      }
    }
    for (std::size_t i = 0; i < pixel_count; ++i) {
      if (segment[i] == geometry::kNoLabel || !on_border[segment[i]]) continue;
      const Eigen::Vector3d p = point[i].head<3>().cast<double>();
      const auto score = [&](std::uint32_t candidate) {
        const SegmentPlane& plane = merged.planes[candidate];
        return std::fabs(plane.normal.dot(p) + plane.offset) /
               distance_allowance(params_.merge, p, plane.normal);
      };
      const std::uint32_t own = pixel_plane[i];
      double best = own == geometry::kNoLabel ? 1.0 : std::min(1.0, score(own));
      for (std::uint32_t k = graph.offsets[segment[i]]; k < graph.offsets[segment[i] + 1]; ++k) {
        const std::uint32_t candidate = merged.segment_plane[graph.neighbours[k]];
        if (candidate == geometry::kNoLabel || candidate == own) continue;
        const double candidate_score = score(candidate);
        if (candidate_score < best) best = candidate_score, pixel_plane[i] = candidate;
      }
    }
  }

  // Output planes: valid, large enough, by decreasing size (then merge order), ids 1..n.
  std::vector<std::uint64_t> pixels_of(merged.planes.size(), 0);
  for (const std::uint32_t m : pixel_plane) {
    if (m != geometry::kNoLabel) ++pixels_of[m];
  }
  std::vector<std::uint32_t> kept;
  for (std::uint32_t i = 0; i < merged.planes.size(); ++i) {
    if (merged.planes[i].valid && pixels_of[i] >= params_.min_plane_pixels) kept.push_back(i);
  }
  std::stable_sort(kept.begin(), kept.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return pixels_of[a] > pixels_of[b]; });
  kept.resize(std::min<std::size_t>(kept.size(), std::numeric_limits<Label>::max()));
  std::vector<Label> plane_label(merged.planes.size(), kUnlabeled);
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const SegmentPlane& fit = merged.planes[kept[k]];
    Plane plane;
    plane.id = static_cast<Label>(k + 1);
    plane.normal = fit.normal;
    plane.offset = fit.offset;
    plane.centroid = fit.centroid;
    plane.major_axis = fit.major_axis;
    plane.minor_axis = fit.minor_axis;
    plane.extent_min = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    plane.extent_max = -plane.extent_min;
    result.planes.push_back(plane);
    plane_label[kept[k]] = plane.id;
  }
  std::vector<double> squared_error(kept.size(), 0.0);
  Label* out = result.labels.data();
  for (std::size_t i = 0; i < pixel_count; ++i) {
    if (pixel_plane[i] == geometry::kNoLabel || plane_label[pixel_plane[i]] == kUnlabeled) continue;
    const Label id = plane_label[pixel_plane[i]];
    out[i] = id;
    Plane& plane = result.planes[id - 1];
    const Eigen::Vector3d d = point[i].head<3>().cast<double>() - plane.centroid;
    const Eigen::Vector2d uv(d.dot(plane.major_axis), d.dot(plane.minor_axis));
    plane.extent_min = plane.extent_min.cwiseMin(uv);
    plane.extent_max = plane.extent_max.cwiseMax(uv);
    const double distance = d.dot(plane.normal);
    squared_error[id - 1] += distance * distance;
    ++plane.inlier_count;
  }
  for (Plane& plane : result.planes) {
    plane.rms_error =
        std::sqrt(squared_error[plane.id - 1] / static_cast<double>(plane.inlier_count));
  }
  result.timings.output = elapsed_ms(clock);
  return result;
}

}  // namespace kartograf::segmentation
