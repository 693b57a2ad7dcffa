#include "kartograf/segmentation/plane_merge.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <string>

#include "compute/cpu_parallel.hpp"
#include "segmentation/plane_join.hpp"

namespace kartograf::segmentation {

namespace {

using detail::allowance;
using geometry::kNoLabel;

// |cos| of the angle between the plane's normal and the ray to its centroid.
double facing(const SegmentPlane& plane) {
  const double range = plane.centroid.norm();
  return range > 0.0 ? std::fabs(plane.normal.dot(plane.centroid)) / range : 1.0;
}

void check_inputs(const SegmentLabelImage& labels, std::uint32_t segment_count,
                  const MergeInputs& inputs) {
  const PointImage* points = inputs.points;
  const std::span<const Eigen::Vector3f> segment_colours = inputs.colours;
  if (labels.size() == 0) {
    require(inputs.segment_at && inputs.graph != nullptr &&
                (segment_count == 0 || !inputs.pixel_sums.empty()),
            "plane merge: without a label image the segments' lookup, neighbour graph and pixel "
            "sums must be given");
  } else {
    require(points == nullptr ||
                (points->width() == labels.width() && points->height() == labels.height()),
            "plane merge: the point image's size differs from the label image's");
  }
  require(segment_colours.empty() || segment_colours.size() == segment_count,
          "plane merge: " + std::to_string(segment_colours.size()) + " segment colours for " +
              std::to_string(segment_count) + " segments");
  require((inputs.fits.empty() || inputs.fits.size() == segment_count) &&
              (inputs.pixel_sums.empty() || inputs.pixel_sums.size() == segment_count),
          "plane merge: the given fits or pixel sums are not one per segment");
  require(inputs.graph == nullptr || inputs.graph->offsets.size() == std::size_t{segment_count} + 1,
          "plane merge: the given neighbour graph is not of the " + std::to_string(segment_count) +
              " segments");
}

// Each segment's own plane fit, and the cosine of its widened angle test (-1: none).
struct SegmentFits {
  std::vector<SegmentPlane> fits;
  std::vector<double> min_cos;
};

// Fits only where a test needs them (most segments of a textured frame are tiny); `given`: the
// caller's fits of every segment (MergeInputs::fits), taken instead of fitting again.
SegmentFits fit_segments(const geometry::SegmentMomentSet& moments, const PlaneMergeParams& params,
                         std::span<const SegmentPlane> given) {
  const std::vector<geometry::SegmentMoments>& segments = moments.segments;
  const auto segment_count = static_cast<std::uint32_t>(segments.size());
  const std::uint64_t min_fit_pixels =
      std::min(params.min_pixels_for_angle, params.min_seed_pixels);
  SegmentFits result{std::vector<SegmentPlane>(segment_count),
                     std::vector<double>(segment_count, -1.0)};
  std::vector<SegmentPlane>& fits = result.fits;
  std::vector<double>& min_cos = result.min_cos;
  compute::detail::for_each_chunk(
      segment_count, segment_count * 64, [&](std::size_t begin, std::size_t end, std::size_t) {
        for (std::size_t s = begin; s < end; ++s) {
          if (segments[s].count < min_fit_pixels) continue;
          fits[s] = given.empty() ? fit_plane(segments[s], moments.origin, params.fit) : given[s];
          if (!fits[s].valid || segments[s].count < params.min_pixels_for_angle) continue;
          const double max_deg =
              params.max_normal_angle_deg + normal_uncertainty_deg(params, fits[s]);
          if (max_deg < 90.0) min_cos[s] = std::cos(max_deg * M_PI / 180.0);
        }
      });
  return result;
}

// The segments large enough to seed a plane, largest first (then by label).
std::vector<std::uint32_t> seed_order(const std::vector<geometry::SegmentMoments>& segments,
                                      const PlaneMergeParams& params) {
  std::vector<std::uint32_t> order;
  for (std::uint32_t s = 0; s < segments.size(); ++s) {
    if (segments[s].count >= params.min_seed_pixels) order.push_back(s);
  }
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return segments[a].count != segments[b].count ? segments[a].count > segments[b].count : a < b;
  });
  return order;
}

// The first pass: each seed starts a plane that grows over neighbouring segments while they pass
// the tests against the plane merged so far.
class PlaneGrower {
 public:
  PlaneGrower(const geometry::SegmentMomentSet& moments, const SegmentFits& fits,
              const SegmentGraph& graph, const PlaneMergeParams& params, MergedPlanes& result)
      : segments_(moments.segments),
        origin_(moments.origin),
        fits_(fits.fits),
        min_cos_(fits.min_cos),
        graph_(graph),
        params_(params),
        min_facing_(std::cos(params.max_incidence_deg * M_PI / 180.0)),
        result_(result) {}

  // A new plane from `seed`, unless it is merged already or may not seed.
  void grow_from(std::uint32_t seed);

 private:
  Eigen::Vector3d centroid_of(const geometry::SegmentMoments& m) const {
    return origin_ + m.sum / static_cast<double>(m.count);
  }
  bool may_seed(std::uint32_t seed) const;
  bool may_join(std::uint32_t s, const SegmentPlane& plane) const;
  void push_unmerged_neighbours(std::uint32_t s);

  const std::vector<geometry::SegmentMoments>& segments_;
  const Eigen::Vector3d& origin_;
  const std::vector<SegmentPlane>& fits_;
  const std::vector<double>& min_cos_;
  const SegmentGraph& graph_;
  const PlaneMergeParams& params_;
  const double min_facing_;
  MergedPlanes& result_;
  std::vector<std::uint32_t> stack_;
};

bool PlaneGrower::may_seed(std::uint32_t seed) const {
  const SegmentPlane& seed_fit = fits_[seed];
  if (result_.segment_plane[seed] != kNoLabel || !seed_fit.valid) return false;
  // Not planar, or seen too near edge-on.
  if (seed_fit.rms_error > allowance(params_, seed_fit.centroid, seed_fit)) return false;
  return !(facing(seed_fit) < min_facing_);
}

// The tests of an unmerged segment s with points against the plane merged so far.
bool PlaneGrower::may_join(std::uint32_t s, const SegmentPlane& plane) const {
  const geometry::SegmentMoments& m = segments_[s];
  if (std::fabs(fits_[s].normal.dot(plane.normal)) < min_cos_[s]) return false;
  const double limit = allowance(params_, centroid_of(m), plane);
  const double ms = mean_squared_distance(m, origin_, plane.normal, plane.offset);
  if (ms > limit * limit) return false;
  if (fits_[s].valid) {
    // As in the second pass: a piece of a perpendicular face near the plane's edge lies
    // within the allowance, yet much farther from the plane than from its own fit.
    const double own_limit = std::max(params_.max_joint_rms_growth * fits_[s].rms_error,
                                      depth_noise(params_, fits_[s].centroid, plane.normal));
    if (ms > own_limit * own_limit) return false;
  }
  const double shift = plane.normal.dot(centroid_of(m)) + plane.offset;
  // Parallel, offset.
  return !(std::fabs(shift) > offset_allowance(params_, centroid_of(m), plane.normal, true));
}

void PlaneGrower::push_unmerged_neighbours(std::uint32_t s) {
  for (std::uint32_t k = graph_.offsets[s]; k < graph_.offsets[s + 1]; ++k) {
    if (result_.segment_plane[graph_.neighbours[k]] == kNoLabel)
      stack_.push_back(graph_.neighbours[k]);
  }
}

void PlaneGrower::grow_from(std::uint32_t seed) {
  if (!may_seed(seed)) return;
  const auto plane_index = static_cast<std::uint32_t>(result_.planes.size());
  geometry::SegmentMoments merged = segments_[seed];
  SegmentPlane plane = fits_[seed];
  std::uint64_t fitted_count = merged.count;
  result_.segment_plane[seed] = plane_index;
  stack_.assign(graph_.neighbours.begin() + graph_.offsets[seed],
                graph_.neighbours.begin() + graph_.offsets[seed + 1]);
  while (!stack_.empty()) {
    const std::uint32_t s = stack_.back();
    stack_.pop_back();
    if (result_.segment_plane[s] != kNoLabel || segments_[s].count == 0) continue;
    if (!may_join(s, plane)) continue;
    result_.segment_plane[s] = plane_index;
    merged += segments_[s];
    // Re-fit as the plane grows by a quarter: deterministic, and few eigen solves.
    if (merged.count * 4 >= fitted_count * 5) {
      const SegmentPlane refit = fit_plane(merged, origin_, params_.fit);
      if (refit.valid) plane = refit;
      fitted_count = merged.count;
    }
    push_unmerged_neighbours(s);
  }
  const SegmentPlane final_fit = fit_plane(merged, origin_, params_.fit);
  result_.moments.push_back(merged);
  result_.planes.push_back(final_fit.valid ? final_fit : plane);
}

// Each plane's colour sum: its segments' mean colours weighted by their pixel counts.
void sum_colours(std::span<const Eigen::Vector3f> segment_colours,
                 const std::vector<geometry::SegmentMoments>& segments, MergedPlanes& result) {
  result.colour_sums.assign(result.planes.size(), Eigen::Vector3d::Zero());
  for (std::uint32_t s = 0; s < segments.size(); ++s) {
    if (result.segment_plane[s] == kNoLabel) continue;
    result.colour_sums[result.segment_plane[s]] +=
        segment_colours[s].cast<double>() * static_cast<double>(segments[s].count);
  }
}

}  // namespace

// The ray's incidence factor of the allowances: |cos| of the angle between the ray to `point` and
// the normal, at least min_facing_factor.
double facing_factor(const PlaneMergeParams& params, const Eigen::Vector3d& point,
                     const Eigen::Vector3d& normal) {
  const double range = point.norm();
  const double facing = range > 0.0 ? std::fabs(normal.dot(point)) / range : 1.0;
  return std::max(facing, params.min_facing_factor);
}

double offset_allowance(const PlaneMergeParams& params, const Eigen::Vector3d& point,
                        const Eigen::Vector3d& normal, bool touching) {
  const double z2 = point.z() * point.z();
  return (touching ? params.offset_base : 0.0) +
         params.max_offset_fraction * distance_allowance(params, point, normal) +
         0.5 * params.depth_step_per_z2 * z2 * facing_factor(params, point, normal);
}

double depth_noise(const PlaneMergeParams& params, const Eigen::Vector3d& point,
                   const Eigen::Vector3d& normal) {
  return params.distance_per_z2 * point.z() * point.z() * facing_factor(params, point, normal);
}

double normal_uncertainty_deg(const PlaneMergeParams& params, const SegmentPlane& plane) {
  // The noise part of the allowance: its base covers slow bending of real surfaces, which
  // does not tilt a small piece's normal.
  const double noise = depth_noise(params, plane.centroid, plane.normal);
  const double half_width = std::sqrt(3.0) * plane.minor_sigma;  // of a uniform strip
  return std::atan2(noise, half_width) * 180.0 / M_PI;
}

double distance_allowance(const PlaneMergeParams& params, const Eigen::Vector3d& point,
                          const Eigen::Vector3d& normal) {
  return (params.distance_base + params.distance_per_z2 * point.z() * point.z()) *
         facing_factor(params, point, normal);
}

void PlaneMergeParams::validate() const {
  require(std::isfinite(max_normal_angle_deg) && max_normal_angle_deg >= 0 &&
              max_normal_angle_deg <= 180,
          "plane merge: max_normal_angle_deg must be in [0, 180], got " +
              std::to_string(max_normal_angle_deg));
  require(std::isfinite(distance_base) && distance_base >= 0,
          "plane merge: distance_base must be >= 0, got " + std::to_string(distance_base));
  require(std::isfinite(distance_per_z2) && distance_per_z2 >= 0,
          "plane merge: distance_per_z2 must be >= 0, got " + std::to_string(distance_per_z2));
  require(distance_base + distance_per_z2 > 0, "plane merge: the distance allowance is zero");
  require(std::isfinite(max_offset_fraction) && max_offset_fraction > 0,
          "plane merge: max_offset_fraction must be positive, got " +
              std::to_string(max_offset_fraction));
  require(std::isfinite(depth_step_per_z2) && depth_step_per_z2 >= 0,
          "plane merge: depth_step_per_z2 must be >= 0, got " + std::to_string(depth_step_per_z2));
  require(std::isfinite(offset_base) && offset_base >= 0,
          "plane merge: offset_base must be >= 0, got " + std::to_string(offset_base));
  require(
      std::isfinite(min_facing_factor) && min_facing_factor > 0 && min_facing_factor <= 1,
      "plane merge: min_facing_factor must be in (0, 1], got " + std::to_string(min_facing_factor));
  require(
      std::isfinite(max_apart_angle_deg) && max_apart_angle_deg >= 0,
      "plane merge: max_apart_angle_deg must be >= 0, got " + std::to_string(max_apart_angle_deg));
  require(std::isfinite(max_joint_rms_growth) && max_joint_rms_growth >= 1,
          "plane merge: max_joint_rms_growth must be >= 1, got " +
              std::to_string(max_joint_rms_growth));
  require(std::isfinite(max_apart_colour_distance) && max_apart_colour_distance >= 0 &&
              std::isfinite(max_see_through_colour_distance) &&
              max_see_through_colour_distance >= 0,
          "plane merge: colour distances must be >= 0");
  require(std::isfinite(max_see_through_fraction) && max_see_through_fraction >= 0 &&
              max_see_through_fraction <= 1,
          "plane merge: max_see_through_fraction must be in [0, 1], got " +
              std::to_string(max_see_through_fraction));
  require(std::isfinite(max_incidence_deg) && max_incidence_deg > 0 && max_incidence_deg <= 90,
          "plane merge: max_incidence_deg must be in (0, 90], got " +
              std::to_string(max_incidence_deg));
}

MergedPlanes merge_segments(const SegmentLabelImage& labels,
                            const geometry::SegmentMomentSet& moments,
                            const PlaneMergeParams& params, const MergeInputs& inputs) {
  params.validate();
  const auto segment_count = static_cast<std::uint32_t>(moments.segments.size());
  check_inputs(labels, segment_count, inputs);
  const SegmentGraph graph = inputs.graph ? *inputs.graph
                             : params.neighbours == NeighbourTest::pixel_adjacency
                                 ? pixel_adjacency_graph(labels, segment_count)
                                 : bounding_box_graph(labels, segment_count);
  const SegmentFits fits = fit_segments(moments, params, inputs.fits);
  MergedPlanes result;
  result.segment_plane.assign(segment_count, kNoLabel);
  PlaneGrower grower(moments, fits, graph, params, result);
  for (const std::uint32_t seed : seed_order(moments.segments, params)) grower.grow_from(seed);
  if (!inputs.colours.empty()) sum_colours(inputs.colours, moments.segments, result);
  result.graph = graph;
  if (params.join_planes)
    detail::join_adjacent_planes(labels, inputs, params, moments.origin, result);
  return result;
}

}  // namespace kartograf::segmentation
