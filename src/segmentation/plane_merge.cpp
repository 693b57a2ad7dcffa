#include "kartograf/segmentation/plane_merge.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>

#include "compute/cpu_parallel.hpp"

namespace kartograf::segmentation {

namespace {

using geometry::kNoLabel;

double allowance(const PlaneMergeParams& params, const Eigen::Vector3d& at,
                 const SegmentPlane& plane) {
  return distance_allowance(params, at, plane.normal);
}

// |cos| of the angle between the plane's normal and the ray to its centroid.
double facing(const SegmentPlane& plane) {
  const double range = plane.centroid.norm();
  return range > 0.0 ? std::fabs(plane.normal.dot(plane.centroid)) / range : 1.0;
}

// Sign-free angle between unit normals at most max_deg (anything at 90 or more).
bool normals_within(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double max_deg) {
  return max_deg >= 90.0 || std::fabs(a.dot(b)) >= std::cos(max_deg * M_PI / 180.0);
}

void add_moments(geometry::SegmentMoments& into, const geometry::SegmentMoments& m) {
  into.count += m.count;
  into.sum += m.sum;
  into.sum_outer += m.sum_outer;
}

// Second pass: joins adjacent merged planes, lowest cost first (cost: RMS of the joint fit over the
// allowance at its depth; joins only below 1 and within the angle). Planes absorbed into another
// are left with count 0 and are compacted by the caller.
void join_adjacent_planes(const SegmentLabelImage& labels, const PointImage* points,
                          const PlaneMergeParams& params, const Eigen::Vector3d& origin,
                          MergedPlanes& merged) {
  const SegmentGraph& graph = merged.graph;
  const std::size_t plane_count = merged.planes.size();
  std::vector<std::uint32_t> alias(plane_count);
  std::iota(alias.begin(), alias.end(), 0u);
  const auto plane_of_segment = [&](std::uint32_t s) {
    std::uint32_t p = merged.segment_plane[s];
    if (p == kNoLabel) return p;
    while (alias[p] != p) p = alias[p];
    return p;
  };
  // Pixel centroids (x, y sums and count) of the planes, for the see-through test: summed at
  // its first use (most frames have no pair that gets that far).
  std::vector<Eigen::Vector3d> pixel_sums;
  const auto sum_pixels = [&] {
    pixel_sums.assign(plane_count, Eigen::Vector3d::Zero());
    for (int y = 0; y < labels.height(); ++y) {
      for (int x = 0; x < labels.width(); ++x) {
        const std::uint32_t s = labels(x, y);
        if (s != kNoLabel && plane_of_segment(s) != kNoLabel)
          pixel_sums[plane_of_segment(s)] += Eigen::Vector3d(x, y, 1.0);
      }
    }
  };
  // Fraction of the valid pixels on the image line between the pixel centroids of p and q, other
  // than theirs, where the camera sees through `plane` (the point lies behind it by more than the
  // allowance): evidence that the plane does not continue between the two pieces.
  const auto see_through = [&](std::uint32_t p, std::uint32_t q, const SegmentPlane& plane) {
    if (pixel_sums.empty()) sum_pixels();
    const Eigen::Vector2d from = pixel_sums[p].head<2>() / pixel_sums[p].z();
    const Eigen::Vector2d to = pixel_sums[q].head<2>() / pixel_sums[q].z();
    const int steps = static_cast<int>(std::ceil((to - from).cwiseAbs().maxCoeff()));
    int valid = 0, behind = 0;
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector2d at = from + (to - from) * (steps > 0 ? double(k) / steps : 0.0);
      const int x = static_cast<int>(std::lround(at.x())),
                y = static_cast<int>(std::lround(at.y()));
      const std::uint32_t s = labels(x, y);
      const std::uint32_t owner = s == kNoLabel ? kNoLabel : plane_of_segment(s);
      const Point4f& point = (*points)(x, y);
      if (owner == p || owner == q || !is_valid(point)) continue;
      const Eigen::Vector3d ray = point.head<3>().cast<double>();
      ++valid;
      const double along = plane.normal.dot(ray);
      if (along == 0.0) continue;
      const double scale = -plane.offset / along;  // the plane's point on this ray: scale * ray
      if (scale > 0.0 && (1.0 - scale) * ray.norm() > allowance(params, ray, plane)) ++behind;
    }
    return valid == 0 ? 0.0 : static_cast<double>(behind) / valid;
  };
  // Planes touch when segments of theirs are adjacent; they are near when both touch one unmerged
  // segment (a gap left by the first pass must not keep two pieces of one plane apart).
  enum Relation : std::uint8_t { apart = 0, near = 1, touching = 2 };
  std::vector<std::vector<std::uint32_t>> adjacent(plane_count), near_planes(plane_count);
  std::vector<std::uint32_t> around;
  for (std::uint32_t s = 0; s + 1 < graph.offsets.size(); ++s) {
    const std::uint32_t p = merged.segment_plane[s];
    around.clear();
    for (std::uint32_t k = graph.offsets[s]; k < graph.offsets[s + 1]; ++k) {
      const std::uint32_t q = merged.segment_plane[graph.neighbours[k]];
      if (q != kNoLabel && q != p) around.push_back(q);
    }
    if (p != kNoLabel) {
      adjacent[p].insert(adjacent[p].end(), around.begin(), around.end());
      continue;
    }
    for (const std::uint32_t a : around) {
      for (const std::uint32_t b : around) {
        if (a != b) near_planes[a].push_back(b);
      }
    }
  }
  // Angle tests are widened by each normal's uncertainty (see normal_uncertainty_deg). A pair
  // passes when the angle between the normals is at most pair_angle + u_p + u_q: each plane keeps
  // the cosine and sine of t_p = pair_angle / 2 + u_p, so that the pair's limit is
  // cos(t_p + t_q) = cos t_p cos t_q - sin t_p sin t_q, with no trigonometry per pair.
  struct AngleShare {
    double cos = 0, sin = 1;
  };
  std::vector<double> uncertainty(plane_count);
  std::vector<std::array<AngleShare, 2>> share(plane_count);  // [0] touching/near, [1] apart
  const auto update_uncertainty = [&](std::uint32_t p) {
    uncertainty[p] =
        merged.planes[p].valid ? normal_uncertainty_deg(params, merged.planes[p]) : 90.0;
    for (int k = 0; k < 2; ++k) {
      const double half = 0.5 * (k == 0 ? params.max_normal_angle_deg : params.max_apart_angle_deg);
      const double t = std::min(90.0, half + uncertainty[p]) * M_PI / 180.0;
      share[p][k] = {std::cos(t), std::sin(t)};
    }
  };
  for (std::uint32_t p = 0; p < plane_count; ++p) update_uncertainty(p);
  const auto pair_within = [&](std::uint32_t p, std::uint32_t q, bool adjacent_pair) {
    const AngleShare& a = share[p][adjacent_pair ? 0 : 1];
    const AngleShare& b = share[q][adjacent_pair ? 0 : 1];
    const double limit = a.cos * b.cos - a.sin * b.sin;  // cos(t_p + t_q); <= 0 beyond 90 deg
    return limit <= 0.0 || std::fabs(merged.planes[p].normal.dot(merged.planes[q].normal)) >= limit;
  };
  // Cost of joining p and q (>= 1: no). Each side must lie within the allowance at its own depth
  // of the joint plane, so a far noisy surface cannot drag a near one along. Pairs that are not
  // near (a plane cut in two by an occluder or a doorway) must also be nearly parallel.
  const auto cost = [&](std::uint32_t p, std::uint32_t q, Relation relation) {
    const bool adjacent_pair = relation != apart;
    const SegmentPlane& a = merged.planes[p];
    const SegmentPlane& b = merged.planes[q];
    if (!a.valid || !b.valid) return 2.0;
    // The cheap tests first (most pairs are apart and fail one of them).
    const bool coloured = !merged.colour_sums.empty();
    const double colour_distance_sq = coloured
                                          ? (merged.colour_sums[p] / static_cast<double>(a.count) -
                                             merged.colour_sums[q] / static_cast<double>(b.count))
                                                .squaredNorm()
                                          : 0.0;
    if (!adjacent_pair &&
        colour_distance_sq > params.max_apart_colour_distance * params.max_apart_colour_distance) {
      return 2.0;
    }
    if (!pair_within(p, q, adjacent_pair)) return 2.0;
    const double limit_a = allowance(params, a.centroid, b),
                 limit_b = allowance(params, b.centroid, a);
    // Cheap necessary test first: each side near the other's plane.
    if (!adjacent_pair && (mean_squared_distance(merged.moments[q], origin, a.normal, a.offset) >
                               4.0 * limit_b * limit_b ||
                           mean_squared_distance(merged.moments[p], origin, b.normal, b.offset) >
                               4.0 * limit_a * limit_a)) {
      return 2.0;
    }
    geometry::SegmentMoments both = merged.moments[p];
    add_moments(both, merged.moments[q]);
    const SegmentPlane joint = fit_plane(both, origin, params.fit);
    // Two parallel pieces with a step between them fit a plane tilted to both: the joint plane
    // itself must keep within the angle of each.
    if (!joint.valid ||
        !normals_within(joint.normal, a.normal, params.max_normal_angle_deg + uncertainty[p]) ||
        !normals_within(joint.normal, b.normal, params.max_normal_angle_deg + uncertainty[q])) {
      return 2.0;
    }
    const auto side = [&](std::uint32_t r, const SegmentPlane& own) {
      const double limit = allowance(params, own.centroid, joint);
      const double rms =
          std::sqrt(mean_squared_distance(merged.moments[r], origin, joint.normal, joint.offset));
      const double shift = std::fabs(joint.normal.dot(own.centroid) + joint.offset);
      // The base term is for sensor bending within one continuous surface, not across a gap.
      return std::max(rms / limit, shift / offset_allowance(params, own.centroid, joint.normal,
                                                            relation == touching));
    };
    // The joint fit may be worse than the parts' own fits only by depth noise: a step or a crease
    // between two well-fitted pieces shows here even when it hides within the allowance.
    const double own_ms = (static_cast<double>(a.count) * a.rms_error * a.rms_error +
                           static_cast<double>(b.count) * b.rms_error * b.rms_error) /
                          static_cast<double>(a.count + b.count);
    const double joint_limit = std::max(params.max_joint_rms_growth * std::sqrt(own_ms),
                                        depth_noise(params, joint.centroid, joint.normal));
    const double result = std::max({joint.rms_error / allowance(params, joint.centroid, joint),
                                    joint.rms_error / joint_limit, side(p, a), side(q, b)});
    // Seen through the gap: one wall on both sides of a doorway, or two coplanar objects.
    if (result < 1.0 && !adjacent_pair && points != nullptr &&
        (!coloured || colour_distance_sq > params.max_see_through_colour_distance *
                                               params.max_see_through_colour_distance) &&
        see_through(p, q, joint) > params.max_see_through_fraction) {
      return 2.0;
    }
    return result;
  };
  // Cached costs of every pair (upper triangle); a join re-evaluates the pairs of the joined plane.
  std::vector<std::uint8_t> is_adjacent(plane_count * plane_count, 0);
  for (std::uint32_t p = 0; p < plane_count; ++p) {
    for (const std::uint32_t q : near_planes[p])
      is_adjacent[p * plane_count + q] = is_adjacent[q * plane_count + p] = near;
  }
  for (std::uint32_t p = 0; p < plane_count; ++p) {
    for (const std::uint32_t q : adjacent[p])
      is_adjacent[p * plane_count + q] = is_adjacent[q * plane_count + p] = touching;
  }
  std::vector<double> pair_cost(plane_count * plane_count, 2.0);
  const auto evaluate = [&](std::uint32_t p, std::uint32_t q) {
    const std::uint32_t lo = std::min(p, q), hi = std::max(p, q);
    const auto relation = static_cast<Relation>(is_adjacent[lo * plane_count + hi]);
    const bool may_join =
        relation != apart ||
        (params.join_apart && merged.moments[lo].count >= params.min_apart_pixels &&
         merged.moments[hi].count >= params.min_apart_pixels);
    pair_cost[lo * plane_count + hi] = may_join ? cost(lo, hi, relation) : 2.0;
  };
  for (std::uint32_t p = 0; p < plane_count; ++p) {
    for (std::uint32_t q = p + 1; q < plane_count; ++q) evaluate(p, q);
  }
  // The cheapest pair of each row (q > p; the first of equal costs), so that finding the next
  // join scans rows, not pairs.
  std::vector<std::uint32_t> row_best(plane_count, kNoLabel);
  const auto cost_of = [&](std::uint32_t p, std::uint32_t q) {
    return q == kNoLabel ? 2.0 : pair_cost[p * plane_count + q];
  };
  const auto update_row = [&](std::uint32_t p) {
    row_best[p] = kNoLabel;
    for (std::uint32_t q = p + 1; q < plane_count; ++q) {
      if (pair_cost[p * plane_count + q] < cost_of(p, row_best[p])) row_best[p] = q;
    }
  };
  for (std::uint32_t p = 0; p < plane_count; ++p) update_row(p);
  for (;;) {
    double best = 1.0;
    std::uint32_t best_p = kNoLabel, best_q = kNoLabel;
    for (std::uint32_t p = 0; p < plane_count; ++p) {
      if (cost_of(p, row_best[p]) < best)
        best = cost_of(p, row_best[p]), best_p = p, best_q = row_best[p];
    }
    if (best_p == kNoLabel) break;
    // q joins p: moments, fit, adjacency and the costs involving either.
    add_moments(merged.moments[best_p], merged.moments[best_q]);
    merged.moments[best_q] = {};
    if (!merged.colour_sums.empty()) merged.colour_sums[best_p] += merged.colour_sums[best_q];
    merged.planes[best_p] = fit_plane(merged.moments[best_p], origin, params.fit);
    merged.planes[best_q] = {};
    if (!pixel_sums.empty()) pixel_sums[best_p] += pixel_sums[best_q];
    update_uncertainty(best_p);
    alias[best_q] = best_p;
    for (std::uint32_t r = 0; r < plane_count; ++r) {
      const std::uint8_t relation =
          std::max(is_adjacent[best_p * plane_count + r], is_adjacent[best_q * plane_count + r]);
      is_adjacent[best_p * plane_count + r] = is_adjacent[r * plane_count + best_p] = relation;
      const std::uint32_t lo = std::min(r, best_q), hi = std::max(r, best_q);
      pair_cost[lo * plane_count + hi] = 2.0;
    }
    is_adjacent[best_p * plane_count + best_p] = 0;
    for (std::uint32_t r = 0; r < plane_count; ++r) {
      if (r != best_p && merged.moments[r].count > 0) evaluate(best_p, r);
    }
    // Rows whose cheapest pair involved p or q start over; the others compare with (r, p).
    for (std::uint32_t r = 0; r < plane_count; ++r) {
      if (r == best_p || row_best[r] == best_p || row_best[r] == best_q) {
        update_row(r);
      } else if (r < best_p) {
        const double changed = pair_cost[r * plane_count + best_p];
        const double current = cost_of(r, row_best[r]);
        if (changed < current || (changed == current && best_p < row_best[r])) row_best[r] = best_p;
      }
    }
    row_best[best_q] = kNoLabel;
  }
  // Compact: drop absorbed planes, renumber in order.
  std::vector<std::uint32_t> renumber(plane_count, kNoLabel);
  MergedPlanes compact;
  for (std::uint32_t p = 0; p < plane_count; ++p) {
    if (merged.moments[p].count == 0) continue;
    renumber[p] = static_cast<std::uint32_t>(compact.planes.size());
    compact.planes.push_back(merged.planes[p]);
    compact.moments.push_back(merged.moments[p]);
    if (!merged.colour_sums.empty()) compact.colour_sums.push_back(merged.colour_sums[p]);
  }
  compact.segment_plane = std::move(merged.segment_plane);
  compact.graph = merged.graph;
  for (std::uint32_t& p : compact.segment_plane) {
    if (p == kNoLabel) continue;
    while (alias[p] != p) p = alias[p];
    p = renumber[p];
  }
  merged = std::move(compact);
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
  const PointImage* points = inputs.points;
  const std::span<const Eigen::Vector3f> segment_colours = inputs.colours;
  require(points == nullptr ||
              (points->width() == labels.width() && points->height() == labels.height()),
          "plane merge: the point image's size differs from the label image's");
  require(segment_colours.empty() || segment_colours.size() == segment_count,
          "plane merge: " + std::to_string(segment_colours.size()) + " segment colours for " +
              std::to_string(segment_count) + " segments");
  const SegmentGraph graph = params.neighbours == NeighbourTest::pixel_adjacency
                                 ? pixel_adjacency_graph(labels, segment_count)
                                 : bounding_box_graph(labels, segment_count);
  const std::vector<geometry::SegmentMoments>& segments = moments.segments;
  const Eigen::Vector3d& origin = moments.origin;
  const double min_facing = std::cos(params.max_incidence_deg * M_PI / 180.0);
  const auto centroid_of = [&](const geometry::SegmentMoments& m) -> Eigen::Vector3d {
    return origin + m.sum / static_cast<double>(m.count);
  };
  // Fits only where a test needs them (most segments of a textured frame are tiny).
  const std::uint64_t min_fit_pixels =
      std::min(params.min_pixels_for_angle, params.min_seed_pixels);
  // Fits, and the cosine of the widened angle test of segments with an angle test.
  std::vector<SegmentPlane> fits(segment_count);
  std::vector<double> min_cos(segment_count, -1.0);
  compute::detail::for_each_chunk(
      segment_count, segment_count * 64, [&](std::size_t begin, std::size_t end, std::size_t) {
        for (std::size_t s = begin; s < end; ++s) {
          if (segments[s].count < min_fit_pixels) continue;
          fits[s] = fit_plane(segments[s], origin, params.fit);
          if (!fits[s].valid || segments[s].count < params.min_pixels_for_angle) continue;
          const double max_deg =
              params.max_normal_angle_deg + normal_uncertainty_deg(params, fits[s]);
          if (max_deg < 90.0) min_cos[s] = std::cos(max_deg * M_PI / 180.0);
        }
      });

  std::vector<std::uint32_t> order;
  for (std::uint32_t s = 0; s < segment_count; ++s) {
    if (segments[s].count >= params.min_seed_pixels) order.push_back(s);
  }
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return segments[a].count != segments[b].count ? segments[a].count > segments[b].count : a < b;
  });

  MergedPlanes result;
  result.segment_plane.assign(segment_count, kNoLabel);
  std::vector<std::uint32_t> stack;
  for (const std::uint32_t seed : order) {
    const SegmentPlane& seed_fit = fits[seed];
    if (result.segment_plane[seed] != kNoLabel || !seed_fit.valid) continue;
    if (seed_fit.rms_error > allowance(params, seed_fit.centroid, seed_fit))
      continue;  // not planar
    if (facing(seed_fit) < min_facing) continue;
    const auto plane_index = static_cast<std::uint32_t>(result.planes.size());
    geometry::SegmentMoments merged = segments[seed];
    SegmentPlane plane = seed_fit;
    std::uint64_t fitted_count = merged.count;
    result.segment_plane[seed] = plane_index;
    stack.assign(graph.neighbours.begin() + graph.offsets[seed],
                 graph.neighbours.begin() + graph.offsets[seed + 1]);
    while (!stack.empty()) {
      const std::uint32_t s = stack.back();
      stack.pop_back();
      if (result.segment_plane[s] != kNoLabel || segments[s].count == 0) continue;
      const geometry::SegmentMoments& m = segments[s];
      if (std::fabs(fits[s].normal.dot(plane.normal)) < min_cos[s]) continue;
      const double limit = allowance(params, centroid_of(m), plane);
      const double ms = mean_squared_distance(m, origin, plane.normal, plane.offset);
      if (ms > limit * limit) continue;
      if (fits[s].valid) {
        // As in the second pass: a piece of a perpendicular face near the plane's edge lies
        // within the allowance, yet much farther from the plane than from its own fit.
        const double own_limit = std::max(params.max_joint_rms_growth * fits[s].rms_error,
                                          depth_noise(params, fits[s].centroid, plane.normal));
        if (ms > own_limit * own_limit) continue;
      }
      const double shift = plane.normal.dot(centroid_of(m)) + plane.offset;
      if (std::fabs(shift) > offset_allowance(params, centroid_of(m), plane.normal, true))
        continue;  // parallel, offset
      result.segment_plane[s] = plane_index;
      add_moments(merged, m);
      // Re-fit as the plane grows by a quarter: deterministic, and few eigen solves.
      if (merged.count * 4 >= fitted_count * 5) {
        const SegmentPlane refit = fit_plane(merged, origin, params.fit);
        if (refit.valid) plane = refit;
        fitted_count = merged.count;
      }
      for (std::uint32_t k = graph.offsets[s]; k < graph.offsets[s + 1]; ++k) {
        if (result.segment_plane[graph.neighbours[k]] == kNoLabel)
          stack.push_back(graph.neighbours[k]);
      }
    }
    const SegmentPlane final_fit = fit_plane(merged, origin, params.fit);
    result.moments.push_back(merged);
    result.planes.push_back(final_fit.valid ? final_fit : plane);
  }
  if (!segment_colours.empty()) {
    result.colour_sums.assign(result.planes.size(), Eigen::Vector3d::Zero());
    for (std::uint32_t s = 0; s < segment_count; ++s) {
      if (result.segment_plane[s] == kNoLabel) continue;
      result.colour_sums[result.segment_plane[s]] +=
          segment_colours[s].cast<double>() * static_cast<double>(segments[s].count);
    }
  }
  result.graph = graph;
  if (params.join_planes) join_adjacent_planes(labels, points, params, origin, result);
  return result;
}

}  // namespace kartograf::segmentation
